//! Farm rendering on Slurm (issue 17): a one-node cluster started by the
//! test renders 4 tiles x 2 frames of a camera move as a job array; one
//! running task is killed with SIGKILL, `quadray farm resume` submits only
//! its tile, the merge job assembles the frames, and they must equal
//! single-machine renders byte for byte, with no finished tile rendered
//! twice. Skipped, with the reason printed, only where Slurm and MUNGE are
//! not installed (`make setup` installs them). Every daemon the test starts
//! is stopped when it ends, also when it fails.

use std::collections::BTreeMap;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Where the Slurm and MUNGE programs are: PATH, then the sbin folders.
fn program(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain(["/usr/sbin", "/sbin", "/usr/local/sbin"].map(PathBuf::from))
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// A one-node Slurm cluster (slurmctld, slurmd) with its own MUNGE daemon,
/// configuration and state in a temporary folder; stopped on drop.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    programs: BTreeMap<&'static str, PathBuf>,
}

impl Cluster {
    const PROGRAMS: [&'static str; 9] =
        ["munged", "mungekey", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo", "scontrol", "scancel"];

    /// Starts the daemons and waits until the node is idle; `Err` with the
    /// reason when Slurm or MUNGE is not installed.
    fn start(dir: &Path) -> Result<Self, String> {
        let mut programs = BTreeMap::new();
        for name in Self::PROGRAMS {
            let p = program(name)
                .ok_or_else(|| format!("{name} is not installed (`make setup` installs Slurm and MUNGE)"))?;
            programs.insert(name, p);
        }
        let dir = dir.to_path_buf();
        for sub in ["munge", "run", "state", "spool", "log"] {
            std::fs::create_dir_all(dir.join(sub)).unwrap();
        }
        let conf = dir.join("slurm.conf");
        let cluster = Self { dir: dir.clone(), conf: conf.clone(), programs };
        let d = |s: &str| dir.join(s).display().to_string();
        let key = d("munge/munge.key");
        cluster.run("mungekey", &["--create", "--keyfile", &key]);
        // --force: the test's folders are not the system's /run/munge.
        cluster.run(
            "munged",
            &[
                "--force",
                &format!("--key-file={key}"),
                &format!("--socket={}", d("run/munge.sock")),
                &format!("--pid-file={}", d("run/munged.pid")),
                &format!("--log-file={}", d("log/munged.log")),
                &format!("--seed-file={}", d("munge/seed")),
            ],
        );
        let user = std::env::var("USER").ok().filter(|u| !u.is_empty()).unwrap_or_else(|| "root".into());
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap().trim().to_string();
        let text = format!(
            "ClusterName=quadraytest\n\
             SlurmctldHost=localhost(127.0.0.1)\n\
             SlurmUser={user}\nSlurmdUser={user}\n\
             AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket={sock}\n\
             SlurmctldPort={p1}\nSlurmdPort={p2}\n\
             StateSaveLocation={state}\nSlurmdSpoolDir={spool}\n\
             SlurmctldPidFile={run}/slurmctld.pid\nSlurmdPidFile={run}/slurmd.pid\n\
             SlurmctldLogFile={log}/slurmctld.log\nSlurmdLogFile={log}/slurmd.log\n\
             ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
             SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\n\
             AccountingStorageType=accounting_storage/none\nJobAcctGatherType=jobacct_gather/none\n\
             JobCompType=jobcomp/none\nMpiDefault=none\nReturnToService=2\n\
             NodeName=qnode NodeHostname={host} NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN\n\
             PartitionName=main Nodes=qnode Default=YES MaxTime=INFINITE State=UP\n",
            sock = d("run/munge.sock"),
            p1 = free_port(),
            p2 = free_port(),
            state = d("state"),
            spool = d("spool"),
            run = d("run"),
            log = d("log"),
        );
        std::fs::write(&conf, text).unwrap();
        cluster.run("slurmctld", &["-i"]);
        cluster.run("slurmd", &["-N", "qnode"]);
        let start = Instant::now();
        loop {
            let state = cluster.output("sinfo", &["--noheader", "--format=%T"]);
            if state.trim() == "idle" {
                break;
            }
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "the node is not idle after 60 s: {state}\n{}",
                cluster.logs()
            );
            std::thread::sleep(Duration::from_millis(200));
        }
        Ok(cluster)
    }

    fn command(&self, name: &str) -> Command {
        let mut cmd = Command::new(&self.programs[name]);
        cmd.env("SLURM_CONF", &self.conf).stdin(Stdio::null());
        cmd
    }

    #[track_caller]
    fn run(&self, name: &str, args: &[&str]) {
        let out = self.command(name).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{name} {args:?} failed: {}\n{}",
            String::from_utf8_lossy(&out.stderr),
            self.logs()
        );
    }

    fn output(&self, name: &str, args: &[&str]) -> String {
        let out = self.command(name).args(args).output().unwrap();
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    /// The daemons' logs' last lines, for failure messages.
    fn logs(&self) -> String {
        ["munged", "slurmctld", "slurmd"]
            .iter()
            .map(|n| {
                let text = std::fs::read_to_string(self.dir.join(format!("log/{n}.log"))).unwrap_or_default();
                let tail: Vec<&str> = text.lines().rev().take(15).collect();
                format!("--- {n}.log (last lines)\n{}", tail.into_iter().rev().collect::<Vec<_>>().join("\n"))
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// The daemons' process ids (from their pid files) that are alive.
    fn alive(&self) -> Vec<(String, i32)> {
        ["slurmd", "slurmctld", "munged"]
            .iter()
            .filter_map(|n| {
                let pid: i32 =
                    std::fs::read_to_string(self.dir.join(format!("run/{n}.pid"))).ok()?.trim().parse().ok()?;
                // A zombie (state Z, its parent has not reaped it) is gone.
                let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
                let state = stat.rsplit_once(") ")?.1.chars().next()?;
                (state != 'Z').then(|| (n.to_string(), pid))
            })
            .collect()
    }

    /// Cancels every job, stops slurmd, slurmctld and munged (SIGTERM, then
    /// SIGKILL after 10 s) and waits until they are gone.
    fn stop(&self) {
        let _ =
            self.command("scancel").args(["--user", &std::env::var("USER").unwrap_or_else(|_| "root".into())]).output();
        for (_, pid) in self.alive() {
            // SAFETY: kill(2) with a daemon's pid from its pid file.
            unsafe { libc::kill(pid, libc::SIGTERM) };
        }
        let start = Instant::now();
        while !self.alive().is_empty() {
            if start.elapsed() > Duration::from_secs(10) {
                for (_, pid) in self.alive() {
                    // SAFETY: as above.
                    unsafe { libc::kill(pid, libc::SIGKILL) };
                }
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        self.stop();
    }
}

fn quadray(args: &[&str], cluster: &Cluster, cwd: &Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_quadray"))
        .args(args)
        .current_dir(cwd)
        .env("SLURM_CONF", &cluster.conf)
        // Inherited by the tasks (sbatch exports the environment).
        .env("QUADRAY_VALIDATION", "1")
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "quadray {args:?} failed:\n{text}");
    text
}

/// The pid of the process running `quadray farm task DIR K`, if any.
fn task_pid(dir: &Path, task: u32) -> Option<i32> {
    let want = ["farm", "task", &dir.display().to_string(), &task.to_string()].join("\0");
    std::fs::read_dir("/proc").ok()?.flatten().find_map(|e| {
        let pid: i32 = e.file_name().to_str()?.parse().ok()?;
        let cmdline = std::fs::read(e.path().join("cmdline")).ok()?;
        String::from_utf8_lossy(&cmdline).contains(&want).then_some(pid)
    })
}

/// Waits until squeue lists no job of the cluster.
fn wait_for_empty_queue(cluster: &Cluster, farm: &Path) {
    let start = Instant::now();
    loop {
        let queue = cluster.output("squeue", &["--noheader", "--array", "--format=%i %T %r"]);
        if queue.trim().is_empty() {
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(900),
            "jobs still queued after 900 s:\n{queue}\n{}\njournal:\n{}",
            cluster.logs(),
            std::fs::read_to_string(farm.join("journal.log")).unwrap_or_default()
        );
        std::thread::sleep(Duration::from_millis(250));
    }
}

fn tile_stamps(farm: &Path) -> BTreeMap<String, (u64, i64, i64)> {
    std::fs::read_dir(farm.join("tiles"))
        .unwrap()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "exr"))
        .map(|e| {
            let m = e.metadata().unwrap();
            (e.file_name().to_string_lossy().into_owned(), (m.ino(), m.mtime(), m.mtime_nsec()))
        })
        .collect()
}

#[test]
fn a_slurm_farm_renders_tiles_and_frames_survives_a_killed_task_and_merges_exact_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let cluster = match Cluster::start(&tmp.path().join("cluster")) {
        Ok(c) => c,
        Err(why) => {
            eprintln!("SKIPPED: {why}");
            return;
        }
    };
    let work = tmp.path().join("work");
    std::fs::create_dir_all(&work).unwrap();
    let scene = format!("{}/scenes/camera_move.toml", env!("CARGO_MANIFEST_DIR"));
    let render = ["--width", "96", "--height", "64", "--spp", "160"];

    // Single-machine references of frames 1 and 2 (this also fills the
    // shader cache the tasks use).
    for f in ["1", "2"] {
        let mut args = vec!["render", &scene, "--frame", f, "-o", "ref", "--validation"];
        args.extend(render);
        quadray(&args, &cluster, &work);
    }

    let farm = work.join("farm");
    let mut args = vec![
        "farm",
        "slurm",
        &scene,
        "--tiles",
        "4",
        "--frames",
        "1-2",
        "-o",
        "farm",
        "--checkpoint-every",
        "0.05",
        "--",
    ];
    args.extend(render);
    let said = quadray(&args, &cluster, &work);
    assert!(said.contains("8 task(s): 0-7"), "{said}");

    // Kill one running task with SIGKILL once it has written a checkpoint.
    let start = Instant::now();
    let victim = 'found: loop {
        for task in 0..8u32 {
            let tile = if task < 4 {
                format!("camera_move.tile-{task}-of-4.0001")
            } else {
                format!("camera_move.tile-{}-of-4.0002", task - 4)
            };
            if farm.join(format!("checkpoints/{tile}.ckpt")).exists() {
                if let Some(pid) = task_pid(&farm, task) {
                    // SAFETY: kill(2) with the task's pid.
                    if unsafe { libc::kill(pid, libc::SIGKILL) } == 0 {
                        break 'found (task, tile);
                    }
                }
            }
        }
        assert!(
            start.elapsed() < Duration::from_secs(600),
            "no task with a checkpoint to kill after 600 s\n{}",
            cluster.logs()
        );
        std::thread::sleep(Duration::from_millis(10));
    };
    wait_for_empty_queue(&cluster, &farm);
    let (victim, victim_tile) = victim;
    assert!(!farm.join(format!("tiles/{victim_tile}.exr")).exists(), "task {victim} finished although killed");
    assert!(farm.join(format!("checkpoints/{victim_tile}.ckpt")).exists(), "the killed task left no checkpoint");
    // The merge job depended on every task: it was cancelled, nothing merged.
    assert!(!farm.join("camera_move.0001.exr").exists() || victim >= 4);
    assert!(!farm.join("camera_move.0002.exr").exists() || victim < 4);
    let before = tile_stamps(&farm);
    assert_eq!(before.len(), 7, "tiles after the kill: {:?}", before.keys());

    let status = quadray(&["farm", "status", "farm"], &cluster, &work);
    eprintln!("{status}");
    let (frame, tile) = (1 + victim / 4, victim % 4);
    let other = 3 - frame;
    assert!(status.contains(&format!("frame {frame}: 3/4 tiles done, tiles [{tile}] checkpointed\n")), "{status}");
    assert!(status.contains(&format!("frame {other}: 4/4 tiles done\n")), "{status}");
    let said = quadray(&["farm", "resume", "farm"], &cluster, &work);
    assert!(said.contains(&format!("1 task(s): {victim}")), "{said}");
    wait_for_empty_queue(&cluster, &farm);
    let journal = std::fs::read_to_string(farm.join("journal.log")).unwrap();
    eprintln!("journal:\n{journal}");

    // Merged frames equal the single-machine renders, byte for byte.
    for f in ["0001", "0002"] {
        for ext in ["exr", "png"] {
            let merged = farm.join(format!("camera_move.{f}.{ext}"));
            let reference = work.join(format!("ref.{f}.{ext}"));
            assert!(merged.exists(), "{} was not merged:\n{journal}\n{}", merged.display(), cluster.logs());
            assert!(
                std::fs::read(&merged).unwrap() == std::fs::read(&reference).unwrap(),
                "{} differs from {}",
                merged.display(),
                reference.display()
            );
        }
    }
    // No finished tile was rendered twice: the seven tiles are the same
    // files (inode and modification time), each task finished once, and
    // only the killed one started twice, the second time from its
    // checkpoint.
    let after = tile_stamps(&farm);
    for (name, stamp) in &before {
        assert_eq!(after.get(name), Some(stamp), "{name} was written again");
    }
    assert_eq!(after.len(), 8);
    for task in 0..8u32 {
        let tag = format!("task {task} (");
        let starts: Vec<&str> = journal.lines().filter(|l| l.starts_with("start ") && l.contains(&tag)).collect();
        let done = journal.lines().filter(|l| l.starts_with("done ") && l.contains(&tag)).count();
        assert_eq!(done, 1, "task {task} finished {done} times:\n{journal}");
        if task == victim {
            assert_eq!(starts.len(), 2, "{journal}");
            assert!(starts[1].ends_with("from its checkpoint"), "{journal}");
        } else {
            assert_eq!(starts.len(), 1, "task {task} started {} times:\n{journal}", starts.len());
        }
    }
    // A farm with everything done submits nothing.
    let said = quadray(&["farm", "resume", "farm"], &cluster, &work);
    assert!(said.contains("nothing to submit"), "{said}");

    cluster.stop();
    assert!(cluster.alive().is_empty());
}

/// Settings that make no farm are refused before anything is written or
/// submitted (no cluster needed).
#[test]
fn bad_farm_settings_are_clear_errors_that_write_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let still = format!("{}/scenes/default.toml", env!("CARGO_MANIFEST_DIR"));
    let moving = format!("{}/scenes/camera_move.toml", env!("CARGO_MANIFEST_DIR"));
    let fails = |args: &[&str], says: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_quadray"))
            .args(args)
            .current_dir(tmp.path())
            // No sbatch reachable: nothing may get as far as submitting.
            .env("PATH", "/nonexistent")
            .stdin(Stdio::null())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "quadray {args:?} should fail");
        assert!(stderr.contains(says), "quadray {args:?}: expected {says:?} in:\n{stderr}");
        assert!(!tmp.path().join("f").exists(), "quadray {args:?} wrote the farm folder");
    };
    fails(&["farm", "slurm", &still, "--tiles", "2", "-o", "f", "--", "--tile", "0/2"], "--tile is set by the farm");
    fails(&["farm", "slurm", &still, "-o", "f", "--", "--checkpoint=x"], "--checkpoint=x is set by the farm");
    fails(&["farm", "slurm", &still, "--frames", "0-1", "-o", "f"], "has no camera animation");
    fails(&["farm", "slurm", &moving, "--tiles", "40", "-o", "f", "--", "--height", "20"], "tile");
    fails(&["farm", "slurm", &moving, "-o", "f", "--", "--spp", "zero"], "--spp");
    fails(&["farm", "resume", "f"], "f: No such file");
    // Without Slurm the folder is set up, and the error says what is missing.
    let out = Command::new(env!("CARGO_BIN_EXE_quadray"))
        .args(["farm", "slurm", &moving, "--tiles", "2", "--frames", "0-1", "-o", "f"])
        .current_dir(tmp.path())
        .env("PATH", "/nonexistent")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("is Slurm installed"), "{stderr}");
    let farm = quadray::jobs::farm::Farm::open(&tmp.path().join("f")).unwrap();
    assert_eq!((farm.manifest.tiles, farm.manifest.frames.clone()), (2, Some(vec![0, 1])));
    assert!(farm.manifest.submissions.is_empty());
    // A dry run needs no Slurm: it prints what it would submit.
    let out = Command::new(env!("CARGO_BIN_EXE_quadray"))
        .args(["farm", "resume", "f", "--dry-run"])
        .current_dir(tmp.path())
        .env("PATH", "/nonexistent")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    assert!(lines[0].starts_with("sbatch ") && lines[0].contains("--array=0-3"), "{stdout}");
    assert!(lines[1].contains("--dependency=afterok:<array job>") && lines[1].ends_with("merge.sh"), "{stdout}");
    assert!(quadray::jobs::farm::Farm::open(&tmp.path().join("f")).unwrap().manifest.submissions.is_empty());
}
