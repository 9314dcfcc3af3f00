//! Farm rendering on Slurm: one render split into tiles and frames, run as
//! an `sbatch` job array (one task per tile of a frame), then merged by a job
//! that depends on the array (`--dependency=afterok`).
//!
//! A farm is a folder:
//!
//! ```text
//! DIR/farm.json                  the manifest: scene, tiles, frames, render flags, submissions
//! DIR/task.sh, DIR/merge.sh      what the array and the merge job run
//! DIR/tiles/NAME.tile-I-of-N[.FFFF].exr        finished tiles
//! DIR/tiles/partial/...          tiles being written (renamed into tiles/ when complete)
//! DIR/checkpoints/...            checkpoints of tasks in progress (resumed by a rerun)
//! DIR/logs/                      Slurm's output of every task and merge job
//! DIR/journal.log                one line per task start, skip and finish
//! DIR/NAME[.FFFF].png, .exr      the merged frames
//! ```
//!
//! Task `k` renders tile `k mod N` of the `k div N`-th frame of the list.
//! Every task is idempotent: it skips a tile already in `tiles/`, writes
//! through `tiles/partial/` and a rename, and resumes its checkpoint when one
//! is left by a task that was stopped (SIGTERM from a pre-empting scheduler
//! writes one at once; otherwise the last periodic one). `resume` submits
//! only the tasks whose tiles are missing, and a new merge job.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The version of `farm.json` this code writes and reads.
pub const MANIFEST_VERSION: u32 = 1;

/// What goes wrong when setting up, submitting or running a farm.
#[derive(Debug, thiserror::Error)]
pub enum FarmError {
    /// A file or folder of the farm could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// `farm.json` is not a manifest this version reads.
    #[error("{path}: not a quadray farm manifest ({why})")]
    Manifest {
        /// The manifest's path.
        path: PathBuf,
        /// What is wrong with it.
        why: String,
    },
    /// The folder already holds another farm.
    #[error(
        "{0} already holds a farm of other settings; use `quadray farm resume {0}` to continue it, or another folder"
    )]
    Exists(PathBuf),
    /// A Slurm command could not be started or failed.
    #[error("`{command}` failed: {why}")]
    Slurm {
        /// The command line.
        command: String,
        /// Its error output, or why it could not start.
        why: String,
    },
    /// Tasks of this farm are still queued or running.
    #[error(
        "jobs {0} of this farm are still queued or running (squeue); resubmitting now would render their tiles \
         twice: wait for them or `scancel` them first"
    )]
    Busy(String),
    /// A task number outside the farm.
    #[error("task {task} is not in this farm (it has {count} tasks)")]
    NoSuchTask {
        /// The task asked for.
        task: u32,
        /// How many tasks the farm has.
        count: u32,
    },
    /// Settings that make no farm.
    #[error("{0}")]
    Invalid(String),
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> FarmError + '_ {
    move |source| FarmError::Io { path: path.to_path_buf(), source }
}

/// One `sbatch` submission: the array job, its tasks and the merge job.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Submission {
    /// The array job's id (empty for a submission of the merge job alone).
    pub array_job: String,
    /// The task numbers submitted in the array.
    pub tasks: Vec<u32>,
    /// The merge job's id.
    pub merge_job: String,
}

/// The settings of a farm, written to `DIR/farm.json` when it is created and
/// read by every task.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Manifest {
    /// [`MANIFEST_VERSION`].
    pub version: u32,
    /// The scene file (absolute).
    pub scene: PathBuf,
    /// The name of the outputs: the scene file's stem.
    pub name: String,
    /// Tiles per frame (`render --tile i/N`).
    pub tiles: u32,
    /// The frames (`render --frame F`), or none for the still camera.
    pub frames: Option<Vec<u32>>,
    /// Further `quadray render` flags of every task (quality, size, seed).
    pub render_args: Vec<String>,
    /// The quadray binary the tasks run (absolute).
    pub quadray: PathBuf,
    /// CPUs per task (`sbatch --cpus-per-task`; lavapipe's threads follow).
    pub cpus_per_task: u32,
    /// Seconds between a task's checkpoints.
    pub checkpoint_every: f64,
    /// Further `sbatch` arguments of every submission (partition, time...).
    pub sbatch_args: Vec<String>,
    /// Every submission so far, the first one first.
    pub submissions: Vec<Submission>,
}

/// One task of the array: a tile of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Task {
    /// The task number (`SLURM_ARRAY_TASK_ID`).
    pub index: u32,
    /// The frame, or none for the still camera.
    pub frame: Option<u32>,
    /// The tile, `0..tiles`.
    pub tile: u32,
}

impl Manifest {
    /// How many tasks the farm has: tiles times frames.
    pub fn task_count(&self) -> u32 {
        self.tiles * self.frames.as_ref().map_or(1, |f| f.len() as u32)
    }

    /// Task `index`: tile `index mod tiles` of the `index div tiles`-th frame.
    pub fn task(&self, index: u32) -> Result<Task, FarmError> {
        if index >= self.task_count() {
            return Err(FarmError::NoSuchTask { task: index, count: self.task_count() });
        }
        let frame = self.frames.as_ref().map(|f| f[(index / self.tiles) as usize]);
        Ok(Task { index, frame, tile: index % self.tiles })
    }

    /// Every task, in order.
    pub fn tasks(&self) -> Vec<Task> {
        (0..self.task_count()).map(|i| self.task(i).expect("in range")).collect()
    }

    /// The tasks of one frame (`None`: the still camera).
    pub fn frame_tasks(&self, frame: Option<u32>) -> Vec<Task> {
        self.tasks().into_iter().filter(|t| t.frame == frame).collect()
    }

    /// The frames to merge: each frame of the list, or the one still frame.
    pub fn frame_list(&self) -> Vec<Option<u32>> {
        self.frames.as_ref().map_or(vec![None], |f| f.iter().copied().map(Some).collect())
    }

    /// A task's `-o` name, `NAME.tile-I-of-N.exr`, without the frame number.
    fn tile_base_name(&self, task: Task) -> PathBuf {
        PathBuf::from(format!("{}.tile-{}-of-{}.exr", self.name, task.tile, self.tiles))
    }

    /// The name of the file a task's render writes: its `-o` name with the
    /// frame number `render --frame` adds.
    fn tile_file_name(&self, task: Task) -> PathBuf {
        let base = self.tile_base_name(task);
        task.frame.map_or_else(|| base.clone(), |f| crate::jobs::output::frame_path(&base, f))
    }

    /// The `quadray render` arguments of a task (after `render`), writing to
    /// `output` (without the frame number, which `render` adds).
    pub fn render_args_of(&self, task: Task, output: &Path, checkpoint: &Path, resume: bool) -> Vec<String> {
        let mut args = vec![
            self.scene.display().to_string(),
            "--tile".into(),
            format!("{}/{}", task.tile, self.tiles),
            "--checkpoint".into(),
            checkpoint.display().to_string(),
            "--checkpoint-every".into(),
            self.checkpoint_every.to_string(),
            "-o".into(),
            output.display().to_string(),
        ];
        if let Some(f) = task.frame {
            args.extend(["--frame".into(), f.to_string()]);
        }
        if resume {
            args.extend(["--resume".into(), checkpoint.display().to_string()]);
        }
        args.extend(self.render_args.iter().cloned());
        args
    }
}

/// The flags a farm sets itself for every task, refused among the render
/// flags it is given.
pub const FARM_OWNED_FLAGS: [&str; 11] = [
    "--tile",
    "--crop",
    "--frame",
    "--frames",
    "--checkpoint",
    "--checkpoint-every",
    "--resume",
    "--time-limit",
    "--bench",
    "--output",
    "-o",
];

/// Refuses render flags that the farm sets itself for each task
/// ([`FARM_OWNED_FLAGS`], alone or as `--flag=value`).
pub fn check_render_args(render_args: &[String]) -> Result<(), FarmError> {
    match render_args.iter().find(|a| FARM_OWNED_FLAGS.contains(&a.split('=').next().unwrap_or_default())) {
        Some(flag) => Err(FarmError::Invalid(format!(
            "{flag} is set by the farm for each task; give it to `quadray farm slurm` (tiles, frames, \
             checkpoints) or leave it out"
        ))),
        None => Ok(()),
    }
}

/// A farm folder and its manifest.
#[derive(Debug, Clone)]
pub struct Farm {
    /// The folder (absolute).
    pub dir: PathBuf,
    /// Its manifest.
    pub manifest: Manifest,
}

impl Farm {
    /// Creates the farm's folders, manifest and scripts in `dir` (created if
    /// missing). A folder that already holds the same farm is reused (so a
    /// repeated `farm slurm` only submits what is missing); one of other
    /// settings is refused.
    pub fn create(dir: &Path, manifest: Manifest) -> Result<Self, FarmError> {
        if manifest.tiles == 0 {
            return Err(FarmError::Invalid("a farm needs at least one tile per frame".into()));
        }
        check_render_args(&manifest.render_args)?;
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let dir = std::fs::canonicalize(dir).map_err(io(dir))?;
        let path = dir.join("farm.json");
        let manifest = if path.exists() {
            let old = Self::open(&dir)?.manifest;
            let same = Manifest { submissions: old.submissions.clone(), ..manifest };
            if same != old {
                return Err(FarmError::Exists(dir));
            }
            old
        } else {
            manifest
        };
        let farm = Self { dir, manifest };
        for sub in ["tiles/partial", "checkpoints", "logs"] {
            let d = farm.dir.join(sub);
            std::fs::create_dir_all(&d).map_err(io(&d))?;
        }
        farm.write_scripts()?;
        farm.save()?;
        Ok(farm)
    }

    /// Opens the farm in `dir`.
    pub fn open(dir: &Path) -> Result<Self, FarmError> {
        let dir = std::fs::canonicalize(dir).map_err(io(dir))?;
        let path = dir.join("farm.json");
        let text = std::fs::read_to_string(&path).map_err(io(&path))?;
        let manifest: Manifest =
            serde_json::from_str(&text).map_err(|e| FarmError::Manifest { path: path.clone(), why: e.to_string() })?;
        if manifest.version != MANIFEST_VERSION {
            return Err(FarmError::Manifest {
                path,
                why: format!("version {}, this quadray reads version {MANIFEST_VERSION}", manifest.version),
            });
        }
        Ok(Self { dir, manifest })
    }

    /// Writes the manifest atomically.
    pub fn save(&self) -> Result<(), FarmError> {
        let path = self.dir.join("farm.json");
        let text = serde_json::to_string_pretty(&self.manifest).expect("a manifest serialises");
        write_atomically(&path, text.as_bytes())
    }

    fn write_scripts(&self) -> Result<(), FarmError> {
        let q = shell_quote(&self.manifest.quadray.display().to_string());
        let d = shell_quote(&self.dir.display().to_string());
        let header = "#!/bin/sh\n# Written by `quadray farm slurm`; submitted with sbatch (see farm.json).\n";
        for (name, body) in [
            ("task.sh", format!("{header}exec {q} farm task {d} \"$SLURM_ARRAY_TASK_ID\"\n")),
            ("merge.sh", format!("{header}exec {q} farm merge {d}\n")),
        ] {
            let path = self.dir.join(name);
            write_atomically(&path, body.as_bytes())?;
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).map_err(io(&path))?;
        }
        Ok(())
    }

    /// A finished tile's path.
    pub fn tile_path(&self, task: Task) -> PathBuf {
        self.dir.join("tiles").join(self.manifest.tile_file_name(task))
    }

    /// The `-o` of a task's render (in `tiles/partial/`, without the frame
    /// number) and the file it writes.
    pub fn partial_paths(&self, task: Task) -> (PathBuf, PathBuf) {
        let partial = self.dir.join("tiles/partial");
        (partial.join(self.manifest.tile_base_name(task)), partial.join(self.manifest.tile_file_name(task)))
    }

    /// A task's checkpoint.
    pub fn checkpoint_path(&self, task: Task) -> PathBuf {
        self.dir.join("checkpoints").join(self.manifest.tile_file_name(task).with_extension("ckpt"))
    }

    /// A merged frame's output name (without extension: PNG and EXR).
    pub fn frame_output(&self, frame: Option<u32>) -> PathBuf {
        // Not output::frame_path: a scene name may hold dots ("a.b"), which
        // that would read as an extension.
        let frame = frame.map_or(String::new(), |f| format!(".{f:04}"));
        self.dir.join(format!("{}{frame}", self.manifest.name))
    }

    /// Whether a frame is merged (its EXR is there).
    fn merged(&self, frame: Option<u32>) -> bool {
        let mut exr = self.frame_output(frame).into_os_string();
        exr.push(".exr");
        PathBuf::from(exr).exists()
    }

    /// The tasks whose tiles are not in `tiles/`.
    pub fn missing_tasks(&self) -> Vec<Task> {
        self.manifest.tasks().into_iter().filter(|t| !self.tile_path(*t).exists()).collect()
    }

    /// The frames not merged yet (their EXR is missing).
    pub fn unmerged_frames(&self) -> Vec<Option<u32>> {
        self.manifest.frame_list().into_iter().filter(|f| !self.merged(*f)).collect()
    }

    /// Appends a line to `journal.log` (one `write`, so lines of concurrent
    /// tasks do not interleave).
    pub fn journal(&self, line: &str) -> Result<(), FarmError> {
        let path = self.dir.join("journal.log");
        let mut f = std::fs::OpenOptions::new().create(true).append(true).open(&path).map_err(io(&path))?;
        f.write_all(format!("{line}\n").as_bytes()).map_err(io(&path))
    }

    /// What a task does before rendering: `None` when its tile is already
    /// there (skip), else whether to resume its checkpoint.
    pub fn prepare_task(&self, task: Task) -> Option<bool> {
        if self.tile_path(task).exists() {
            return None;
        }
        Some(self.checkpoint_path(task).exists())
    }

    /// Moves a task's finished tile from `tiles/partial/` into `tiles/`.
    pub fn finish_task(&self, task: Task) -> Result<(), FarmError> {
        let (_, written) = self.partial_paths(task);
        let done = self.tile_path(task);
        std::fs::rename(&written, &done).map_err(io(&written))
    }

    /// Submits the tasks whose tiles are missing as a job array, then a
    /// merge job that runs once all of them succeeded (or the merge job
    /// alone when every tile is there but a frame is not merged). Refuses
    /// while jobs of earlier submissions are queued or running. Returns the
    /// submission, or `None` when there is nothing left to do.
    pub fn submit(&mut self) -> Result<Option<Submission>, FarmError> {
        let active = self.active_jobs()?;
        if !active.is_empty() {
            return Err(FarmError::Busy(active.join(", ")));
        }
        let Some(missing) = self.pending() else { return Ok(None) };
        let array_job = if missing.is_empty() { String::new() } else { run_slurm(&mut self.array_command(&missing))? };
        let merge_job = run_slurm(&mut self.merge_command(Some(array_job.as_str()).filter(|a| !a.is_empty())))?;
        let submission = Submission { array_job, tasks: missing, merge_job };
        self.manifest.submissions.push(submission.clone());
        self.save()?;
        Ok(Some(submission))
    }

    /// What [`Farm::submit`] would run now, as command lines (the merge
    /// job's dependency names the array job as `<array job>`), without
    /// asking Slurm anything; empty when there is nothing to submit.
    pub fn plan(&self) -> Vec<String> {
        let Some(missing) = self.pending() else { return Vec::new() };
        let mut lines = Vec::new();
        if !missing.is_empty() {
            lines.push(command_line(&self.array_command(&missing)));
        }
        lines.push(command_line(&self.merge_command((!missing.is_empty()).then_some("<array job>"))));
        lines
    }

    /// The task numbers a submission renders now (empty when only the merge
    /// is left), or `None` when every tile is there and every frame merged.
    fn pending(&self) -> Option<Vec<u32>> {
        let missing: Vec<u32> = self.missing_tasks().iter().map(|t| t.index).collect();
        (!missing.is_empty() || !self.unmerged_frames().is_empty()).then_some(missing)
    }

    /// An `sbatch` command with the options of every submission.
    fn sbatch(&self) -> Command {
        let mut cmd = Command::new("sbatch");
        // The tasks start from the user's Vulkan environment (Slurm passes
        // the submitter's on).
        crate::vk::runtime::restore_env(&mut cmd);
        cmd.arg("--parsable")
            .arg(format!("--job-name=quadray-{}", self.manifest.name))
            .arg(format!("--cpus-per-task={}", self.manifest.cpus_per_task))
            .arg(format!("--chdir={}", self.dir.display()))
            .args(&self.manifest.sbatch_args);
        cmd
    }

    /// The job array of the tasks `missing`.
    fn array_command(&self, missing: &[u32]) -> Command {
        let mut cmd = self.sbatch();
        cmd.arg(format!("--array={}", array_spec(missing)))
            .arg(format!("--output={}", self.dir.join("logs/task-%A_%a.log").display()))
            .arg(self.dir.join("task.sh"));
        cmd
    }

    /// The merge job, after `array_job` when there is one.
    fn merge_command(&self, array_job: Option<&str>) -> Command {
        let mut cmd = self.sbatch();
        if let Some(job) = array_job {
            cmd.arg(format!("--dependency=afterok:{job}")).arg("--kill-on-invalid-dep=yes");
        }
        cmd.arg(format!("--output={}", self.dir.join("logs/merge-%j.log").display())).arg(self.dir.join("merge.sh"));
        cmd
    }

    /// The jobs of this farm's submissions that `squeue` still lists.
    pub fn active_jobs(&self) -> Result<Vec<String>, FarmError> {
        let ids: Vec<&str> = self
            .manifest
            .submissions
            .iter()
            .flat_map(|s| [s.array_job.as_str(), s.merge_job.as_str()])
            .filter(|s| !s.is_empty())
            .collect();
        if ids.is_empty() {
            return Ok(Vec::new());
        }
        let mut cmd = Command::new("squeue");
        cmd.args(["--noheader", "--array", "--format=%i %T", "--jobs"]).arg(ids.join(","));
        let out = run_slurm(&mut cmd)?;
        Ok(out.lines().map(|l| l.trim().to_string()).filter(|l| !l.is_empty()).collect())
    }

    /// A report of the farm: per frame, the tiles done, with a checkpoint
    /// and missing, and whether it is merged.
    pub fn status(&self) -> String {
        let mut s = String::new();
        let m = &self.manifest;
        let _ = writeln!(
            s,
            "farm {}: {} x {} tile(s) of {}, {} submission(s)",
            self.dir.display(),
            m.frames.as_ref().map_or(1, Vec::len),
            m.tiles,
            m.scene.display(),
            m.submissions.len()
        );
        for frame in m.frame_list() {
            let state: Vec<(u32, Option<bool>)> =
                m.frame_tasks(frame).into_iter().map(|t| (t.tile, self.prepare_task(t))).collect();
            let done = state.iter().filter(|s| s.1.is_none()).count();
            let ckpt: Vec<u32> = state.iter().filter(|s| s.1 == Some(true)).map(|s| s.0).collect();
            let merged = self.merged(frame);
            let _ = writeln!(
                s,
                "  {}: {}/{} tiles done{}{}",
                frame.map_or("still".to_string(), |f| format!("frame {f}")),
                done,
                m.tiles,
                if ckpt.is_empty() { String::new() } else { format!(", tiles {ckpt:?} checkpointed") },
                if merged { ", merged" } else { "" }
            );
        }
        s
    }
}

/// A command as one line, its arguments quoted for `sh` where needed.
fn command_line(cmd: &Command) -> String {
    let quote = |s: &std::ffi::OsStr| {
        let s = s.to_string_lossy();
        if s.chars().all(|c| c.is_ascii_alphanumeric() || "-_=./:%,".contains(c)) {
            s.into_owned()
        } else {
            shell_quote(&s)
        }
    };
    std::iter::once(cmd.get_program()).chain(cmd.get_args()).map(quote).collect::<Vec<_>>().join(" ")
}

/// Runs a Slurm command and returns its standard output (trimmed; for
/// `sbatch --parsable`, the job id before any `;cluster`).
fn run_slurm(cmd: &mut Command) -> Result<String, FarmError> {
    let line = command_line(cmd);
    let out = cmd.output().map_err(|e| FarmError::Slurm {
        command: line.clone(),
        why: format!("{e} (is Slurm installed and on PATH? `make setup` installs slurm-client)"),
    })?;
    if !out.status.success() {
        return Err(FarmError::Slurm { command: line, why: String::from_utf8_lossy(&out.stderr).trim().to_string() });
    }
    let text = String::from_utf8_lossy(&out.stdout).trim().to_string();
    Ok(text.split(';').next().unwrap_or_default().to_string())
}

/// A Slurm `--array` list of task numbers: runs collapsed, e.g. `0-3,5,7-9`.
pub fn array_spec(ids: &[u32]) -> String {
    let mut ids = ids.to_vec();
    ids.sort_unstable();
    ids.dedup();
    let mut out = Vec::new();
    let mut i = 0;
    while i < ids.len() {
        let mut j = i;
        while j + 1 < ids.len() && ids[j + 1] == ids[j] + 1 {
            j += 1;
        }
        out.push(if i == j { ids[i].to_string() } else { format!("{}-{}", ids[i], ids[j]) });
        i = j + 1;
    }
    out.join(",")
}

/// `s` quoted for `sh`.
fn shell_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// Writes `bytes` to `path` through a temporary file in the same folder and
/// a rename.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), FarmError> {
    crate::util::files::write_file_atomically(path, bytes).map_err(io(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest(frames: Option<Vec<u32>>) -> Manifest {
        Manifest {
            version: MANIFEST_VERSION,
            scene: "/s/move.toml".into(),
            name: "move".into(),
            tiles: 4,
            frames,
            render_args: vec!["--spp".into(), "8".into()],
            quadray: "/bin/quadray".into(),
            cpus_per_task: 1,
            checkpoint_every: 60.0,
            sbatch_args: Vec::new(),
            submissions: Vec::new(),
        }
    }

    #[test]
    fn tasks_are_tiles_of_frames_in_order() {
        let m = manifest(Some(vec![3, 5]));
        assert_eq!(m.task_count(), 8);
        assert_eq!(m.task(0).unwrap(), Task { index: 0, frame: Some(3), tile: 0 });
        assert_eq!(m.task(5).unwrap(), Task { index: 5, frame: Some(5), tile: 1 });
        assert!(matches!(m.task(8), Err(FarmError::NoSuchTask { task: 8, count: 8 })));
        assert_eq!(m.frame_tasks(Some(5)).iter().map(|t| t.index).collect::<Vec<_>>(), [4, 5, 6, 7]);
        let still = manifest(None);
        assert_eq!(still.task_count(), 4);
        assert_eq!(still.task(3).unwrap().frame, None);
        assert_eq!(still.frame_list(), [None]);
    }

    #[test]
    fn array_specs_collapse_runs() {
        assert_eq!(array_spec(&[0, 1, 2, 3]), "0-3");
        assert_eq!(array_spec(&[7, 5, 0, 1, 9, 8, 1]), "0-1,5,7-9");
        assert_eq!(array_spec(&[4]), "4");
    }

    #[test]
    fn task_render_arguments_name_tile_frame_and_checkpoint() {
        let m = manifest(Some(vec![3, 5]));
        let args = m.render_args_of(m.task(6).unwrap(), Path::new("/o/x.exr"), Path::new("/c/x.ckpt"), true);
        let line = args.join(" ");
        assert_eq!(
            line,
            "/s/move.toml --tile 2/4 --checkpoint /c/x.ckpt --checkpoint-every 60 -o /o/x.exr --frame 5 --resume \
             /c/x.ckpt --spp 8"
        );
    }

    #[test]
    fn a_farm_refuses_flags_it_sets_and_other_settings_in_its_folder() {
        let dir = tempfile::tempdir().unwrap();
        let mut m = manifest(None);
        m.render_args = vec!["--tile=1/2".into()];
        assert!(matches!(Farm::create(dir.path(), m), Err(FarmError::Invalid(_))));
        let farm = Farm::create(dir.path(), manifest(None)).unwrap();
        assert!(farm.dir.join("task.sh").exists() && farm.dir.join("tiles/partial").is_dir());
        // The same settings again: the same farm.
        assert_eq!(Farm::create(dir.path(), manifest(None)).unwrap().manifest, farm.manifest);
        let mut other = manifest(None);
        other.tiles = 2;
        assert!(matches!(Farm::create(dir.path(), other), Err(FarmError::Exists(_))));
        assert_eq!(Farm::open(dir.path()).unwrap().manifest, farm.manifest);
    }

    #[test]
    fn a_plan_lists_the_array_and_the_merge_job_without_slurm() {
        let dir = tempfile::tempdir().unwrap();
        let farm = Farm::create(dir.path(), manifest(Some(vec![3, 5]))).unwrap();
        let plan = farm.plan();
        assert_eq!(plan.len(), 2, "{plan:?}");
        assert!(plan[0].starts_with("sbatch --parsable --job-name=quadray-move --cpus-per-task=1"), "{}", plan[0]);
        assert!(plan[0].contains(" --array=0-7 ") && plan[0].ends_with("task.sh"), "{}", plan[0]);
        assert!(plan[1].contains("'--dependency=afterok:<array job>' --kill-on-invalid-dep=yes"), "{}", plan[1]);
        assert!(plan[1].ends_with("merge.sh"), "{}", plan[1]);
    }

    #[test]
    fn shell_quoting_survives_quotes() {
        assert_eq!(shell_quote("/a b/it's"), r"'/a b/it'\''s'");
    }
}
