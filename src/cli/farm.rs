//! `quadray farm`: Slurm job arrays of tiles and frames (`quadray::jobs::farm`).

use std::path::PathBuf;

use super::common::*;
use super::images::*;
use super::render::*;
use anyhow::{bail, Context as _, Result};
use clap::{Parser, Subcommand};
use quadray::model::scene::MAX_IMAGE_SIZE;

/// `quadray farm`: Slurm job arrays of tiles and frames.
#[derive(Subcommand, Debug)]
pub(crate) enum FarmCommand {
    /// Set up a farm folder and submit it: `sbatch` job array of tiles x
    /// frames, then a merge job that runs when every task succeeded. Run it
    /// again (or `farm resume`) after failures: only missing tiles are
    /// submitted.
    Slurm(FarmSlurmArgs),
    /// Submit the tasks of a farm whose tiles are missing (after failed,
    /// cancelled or pre-empted tasks), and a new merge job.
    Resume {
        /// The farm folder.
        dir: PathBuf,
        /// Print the sbatch commands instead of running them.
        #[arg(long)]
        dry_run: bool,
    },
    /// Print a farm's progress: per frame, the tiles done and checkpointed,
    /// and whether it is merged.
    Status {
        /// The farm folder.
        dir: PathBuf,
    },
    /// One task of the array (what task.sh runs): renders its tile of its
    /// frame unless it is already there, resuming its checkpoint if any.
    #[command(hide = true)]
    Task {
        /// The farm folder.
        dir: PathBuf,
        /// The task number (SLURM_ARRAY_TASK_ID).
        index: u32,
    },
    /// Merge every frame whose tiles are all there into DIR/NAME[.FFFF].png
    /// and .exr (what merge.sh runs); fails, naming them, when tiles are
    /// missing.
    Merge {
        /// The farm folder.
        dir: PathBuf,
    },
}

#[derive(Parser, Debug)]
pub(crate) struct FarmSlurmArgs {
    /// Scene file (TOML, see scenes/README.md).
    pub(crate) scene: PathBuf,
    /// Tiles per frame (`render --tile i/N`: bands of whole rows).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIZE))]
    pub(crate) tiles: u32,
    /// Frames of the scene's camera animation, A-B or A-B:STEP; without it,
    /// the still camera.
    #[arg(long)]
    pub(crate) frames: Option<FrameRange>,
    /// The farm folder: tiles, checkpoints, logs, merged frames.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// CPUs per task (`sbatch --cpus-per-task`; lavapipe runs two threads per CPU).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub(crate) cpus_per_task: u32,
    /// Seconds between a task's checkpoints (what a task killed without
    /// warning loses at most; SIGTERM writes one at once).
    #[arg(long, default_value_t = 120.0, value_parser = positive_seconds)]
    pub(crate) checkpoint_every: f64,
    /// A further `sbatch` argument for every submission, e.g.
    /// `--sbatch-arg=--partition=render` (repeatable).
    #[arg(long = "sbatch-arg", allow_hyphen_values = true)]
    pub(crate) sbatch_args: Vec<String>,
    /// Set up the farm folder and print the sbatch commands instead of
    /// running them (needs no Slurm).
    #[arg(long)]
    pub(crate) dry_run: bool,
    /// `quadray render` flags of every task, after `--`: quality, size,
    /// seed (e.g. `-- --spp 256 --width 1920 --height 1080`).
    #[arg(last = true)]
    pub(crate) render_args: Vec<String>,
}

/// `quadray farm`.
pub(crate) fn farm(cmd: FarmCommand) -> Result<()> {
    use quadray::jobs::farm::{Farm, Manifest, MANIFEST_VERSION};
    match cmd {
        FarmCommand::Slurm(args) => {
            let scene =
                std::fs::canonicalize(&args.scene).with_context(|| format!("scene file {}", args.scene.display()))?;
            let frames = args.frames.map(FrameRange::frames);
            // Flags the farm sets itself would otherwise meet clap's "used
            // more than once" below.
            quadray::jobs::farm::check_render_args(&args.render_args)?;
            // The tasks' render command, checked here (flags, scene, tiles)
            // rather than in every task.
            let mut check = vec!["quadray".to_string(), "render".into(), scene.display().to_string()];
            check.extend(args.render_args.iter().cloned());
            check.extend(["--tile".into(), format!("0/{}", args.tiles)]);
            if let Some(f) = frames.as_ref() {
                check.extend(["--frame".into(), f[0].to_string()]);
            }
            let render_args = RenderArgs::try_parse_from(&check[1..])?;
            let loaded = load(&render_args)?;
            quadray::passes::PixelBounds::tile(0, args.tiles, loaded.image.width, loaded.image.height)?;
            if frames.is_some() && loaded.camera.keyframes.is_empty() {
                bail!("--frames: {} has no camera animation ([[camera.keyframes]], scenes/README.md)", scene.display());
            }
            let manifest = Manifest {
                version: MANIFEST_VERSION,
                name: scene.file_stem().map_or("render".into(), |s| s.to_string_lossy().into_owned()),
                scene,
                tiles: args.tiles,
                frames,
                render_args: args.render_args,
                quadray: quadray::vk::runtime::current_exe().context("cannot find the quadray binary")?,
                cpus_per_task: args.cpus_per_task,
                checkpoint_every: args.checkpoint_every,
                sbatch_args: args.sbatch_args,
                submissions: Vec::new(),
            };
            let mut farm = Farm::create(&args.output, manifest)?;
            farm_submit(&mut farm, args.dry_run)
        }
        FarmCommand::Resume { dir, dry_run } => farm_submit(&mut Farm::open(&dir)?, dry_run),
        FarmCommand::Status { dir } => {
            print!("{}", Farm::open(&dir)?.status());
            Ok(())
        }
        FarmCommand::Task { dir, index } => {
            let farm = Farm::open(&dir)?;
            let task = farm.manifest.task(index)?;
            let what = format!(
                "task {index} ({}tile {}/{})",
                task.frame.map_or(String::new(), |f| format!("frame {f}, ")),
                task.tile,
                farm.manifest.tiles
            );
            let Some(resume) = farm.prepare_task(task) else {
                farm.journal(&format!("skip {what}: its tile is there"))?;
                eprintln!("{what}: {} is there already; nothing to do", farm.tile_path(task).display());
                return Ok(());
            };
            farm.journal(&format!("start {what}{}", if resume { " from its checkpoint" } else { "" }))?;
            let (output, _) = farm.partial_paths(task);
            let mut argv = vec!["quadray".to_string(), "render".into()];
            argv.extend(farm.manifest.render_args_of(task, &output, &farm.checkpoint_path(task), resume));
            eprintln!("{what}: quadray {}", argv[1..].join(" "));
            let args = RenderArgs::try_parse_from(&argv[1..])?;
            // Exits with status 75 (and the checkpoint written) when stopped.
            render(args)?;
            farm.finish_task(task)?;
            farm.journal(&format!("done {what}"))?;
            Ok(())
        }
        FarmCommand::Merge { dir } => {
            let farm = Farm::open(&dir)?;
            let missing = farm.missing_tasks();
            for frame in farm.manifest.frame_list() {
                let tasks = farm.manifest.frame_tasks(frame);
                if tasks.iter().any(|t| missing.contains(t)) {
                    continue;
                }
                merge(MergeArgs {
                    tiles: tasks.iter().map(|t| farm.tile_path(*t)).collect(),
                    output: farm.frame_output(frame),
                    half: false,
                })?;
            }
            if !missing.is_empty() {
                let list: Vec<String> = missing.iter().map(|t| t.index.to_string()).collect();
                bail!(
                    "tiles of tasks {} are missing; `quadray farm resume {}` renders them",
                    list.join(", "),
                    farm.dir.display()
                );
            }
            Ok(())
        }
    }
}

/// Submits what a farm lacks and says what was submitted.
pub(crate) fn farm_submit(farm: &mut quadray::jobs::farm::Farm, dry_run: bool) -> Result<()> {
    let nothing = |farm: &quadray::jobs::farm::Farm| {
        eprintln!("farm {}: every tile is rendered and every frame merged; nothing to submit", farm.dir.display())
    };
    if dry_run {
        let plan = farm.plan();
        if plan.is_empty() {
            nothing(farm);
        }
        for line in plan {
            println!("{line}");
        }
        return Ok(());
    }
    match farm.submit()? {
        None => nothing(farm),
        Some(s) => {
            if s.array_job.is_empty() {
                eprintln!("every tile is there: submitted merge job {}", s.merge_job);
            } else {
                eprintln!(
                    "submitted job array {} ({} task(s): {}) and merge job {} (runs once every task succeeded)",
                    s.array_job,
                    s.tasks.len(),
                    quadray::jobs::farm::array_spec(&s.tasks),
                    s.merge_job
                );
            }
            eprintln!(
                "`quadray farm status {0}` shows progress; after failures `quadray farm resume {0}` submits what is missing",
                farm.dir.display()
            );
        }
    }
    Ok(())
}
