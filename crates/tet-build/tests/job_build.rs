//! A job end to end: plan, parts built in reverse order by separate calls
//! (as separate processes would), merge, against the single-process
//! streamed build of the same plan; failed, stale, half-written and
//! killed parts are named, rebuilt alone, and the merge comes out byte for
//! byte the same; a part stuck in TetGen is cured by planning again.

#![cfg(feature = "tetgen")]

mod common;

use std::path::Path;
use std::time::Duration;

use tet_build::outofcore::job::{
    JobError, JobManifest, PartOutcome, PartState, PlanOptions, RunningRecord, build_part,
    job_status, merge_job, plan_job,
};
use tet_build::outofcore::memory_model::knot_grid;
use tet_build::outofcore::seam::SeamOptions;
use tet_build::outofcore::stream::StreamOptions;
use tet_build::outofcore::tree::build_tree_to_file;
use tet_build::tetgen::{Isolation, WorkerCommand};

fn worker() -> Isolation {
    Isolation::Worker(WorkerCommand {
        program: env!("CARGO_BIN_EXE_tet-build-worker").into(),
        args: vec![],
        timeout: Some(Duration::from_secs(600)),
    })
}

fn build_all(dir: &Path, job: &JobManifest, order: impl Iterator<Item = usize>) {
    for k in order {
        match build_part(dir, job, k, &worker()).unwrap() {
            PartOutcome::Built(r) => {
                assert_eq!(r.part, k);
                assert!(r.tets > 0);
                assert!(r.tetgen_peak_kib.is_some_and(|kib| kib > 0), "{r:?}");
            }
            PartOutcome::Skipped(r) => panic!("part {k} skipped on its first run: {r:?}"),
        }
    }
}

fn not_ready(e: JobError) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    match e {
        JobError::PartsNotReady {
            missing,
            failed,
            stale,
            running,
        } => {
            assert!(running.is_empty(), "running {running:?}");
            (missing, failed, stale)
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn parts_in_any_order_merge_into_the_single_process_build() {
    let scene = knot_grid(1, 120, 12);
    let dir = tempfile::tempdir().unwrap();
    let jobdir = dir.path().join("job");
    let job = plan_job(
        &scene,
        &PlanOptions {
            parts: 4,
            ..PlanOptions::default()
        },
        &jobdir,
    )
    .unwrap();
    let n = job.parts.len();
    assert!(n >= 4, "{n} parts");

    // Nothing built yet: the merge names every part.
    let out = dir.path().join("job.tmesh");
    let (missing, _, _) = not_ready(merge_job(&jobdir, &job, &out).unwrap_err());
    assert_eq!(missing, (0..n).collect::<Vec<_>>());
    assert!(!out.exists());

    build_all(&jobdir, &job, (0..n).rev());
    let summary = merge_job(&jobdir, &job, &out).unwrap();
    let merged = tet_core::format::load(&out).unwrap();
    assert_eq!(summary.tets, merged.tets.len() as u64);

    // The single-process streamed build of the same cut tree.
    let tree = match &job.partition {
        tet_build::outofcore::job::manifest::Partition::Tree { tree, .. } => tree.cut_tree(),
        other => panic!("{other:?}"),
    };
    let local_out = dir.path().join("local.tmesh");
    let options = SeamOptions {
        isolation: worker(),
        ..SeamOptions::default()
    };
    build_tree_to_file(&scene, &tree, &options, &StreamOptions::new(&local_out)).unwrap();
    let local = tet_core::format::load(&local_out).unwrap();
    assert!(
        common::canonical(&merged) == common::canonical(&local),
        "the job's mesh differs from the single-process build's"
    );
    // Same parts, same order, same sort: the very same file.
    assert_eq!(
        std::fs::read(&out).unwrap(),
        std::fs::read(&local_out).unwrap()
    );

    // Running a finished part again does nothing.
    assert!(matches!(
        build_part(&jobdir, &job, 0, &worker()).unwrap(),
        PartOutcome::Skipped(_)
    ));
}

#[test]
fn broken_parts_are_named_and_rebuilt_alone() {
    let scene = knot_grid(1, 60, 8);
    let dir = tempfile::tempdir().unwrap();
    let jobdir = dir.path().join("job");
    let options = PlanOptions {
        parts: 4,
        ..PlanOptions::default()
    };
    let job = plan_job(&scene, &options, &jobdir).unwrap();
    let n = job.parts.len();
    assert!(n >= 4, "{n} parts");
    build_all(&jobdir, &job, 0..n);
    let first = dir.path().join("first.tmesh");
    merge_job(&jobdir, &job, &first).unwrap();
    let reference = std::fs::read(&first).unwrap();
    let out = dir.path().join("again.tmesh");
    let paths = |k| job.part_paths(&jobdir, k);
    let mtime = |k| {
        std::fs::metadata(paths(k).result)
            .unwrap()
            .modified()
            .unwrap()
    };

    // Part 1 half-written (a result cut short under its done record), part
    // 2 killed before its record (result and temporary file left, no
    // done record).
    let r1 = std::fs::read(paths(1).result).unwrap();
    std::fs::write(paths(1).result, &r1[..r1.len() / 2]).unwrap();
    std::fs::remove_file(paths(2).done).unwrap();
    std::fs::write(jobdir.join("part-2.tmesh.tmp999"), b"partial").unwrap();
    let states = job_status(&jobdir, &job, false).unwrap();
    assert!(matches!(states[0], PartState::Done(_)));
    assert!(
        matches!(states[1], PartState::Stale(ref why) if why.contains("bytes")),
        "{states:?}"
    );
    assert_eq!(states[2], PartState::Missing);
    let (missing, failed, stale) = not_ready(merge_job(&jobdir, &job, &out).unwrap_err());
    assert_eq!((missing, failed, stale), (vec![2], vec![], vec![1]));
    assert!(!out.exists());

    // A run of part 2 in progress: a live process here (this one), or a
    // process on another host, is running; a process here that is gone
    // (killed before it could remove its record) is not.
    let live = RunningRecord::this_process(2);
    let elsewhere = RunningRecord {
        host: format!("{}-other", live.host),
        pid: 1,
        ..live.clone()
    };
    let mut dead = live.clone();
    dead.process_start = dead.process_start.map(|t| t + 1);
    for (record, running) in [(&live, true), (&elsewhere, true), (&dead, false)] {
        std::fs::write(paths(2).running, serde_json::to_string(record).unwrap()).unwrap();
        let state = &job_status(&jobdir, &job, false).unwrap()[2];
        if running {
            assert_eq!(state, &PartState::Running(record.clone()));
            let e = merge_job(&jobdir, &job, &out).unwrap_err();
            assert!(e.to_string().ends_with("; running 2"), "{e}");
            assert_eq!(e.rerun(), vec![1], "a running part is not run again");
        } else {
            assert_eq!(state, &PartState::Missing, "{record:?}");
        }
    }

    // A result with the right length but other bytes: only the digest
    // tells (the merge checks it; the quick status does not).
    let r0 = std::fs::read(paths(0).result).unwrap();
    let mut bad = r0.clone();
    let at = bad.len() - 5;
    bad[at] ^= 1;
    std::fs::write(paths(0).result, &bad).unwrap();
    assert!(matches!(
        job_status(&jobdir, &job, false).unwrap()[0],
        PartState::Done(_)
    ));
    assert!(matches!(
        job_status(&jobdir, &job, true).unwrap()[0],
        PartState::Stale(_)
    ));
    let (_, _, stale) = not_ready(merge_job(&jobdir, &job, &out).unwrap_err());
    assert_eq!(stale, vec![0, 1]);

    // A part whose input is damaged fails with a typed error and a record.
    let input = std::fs::read(paths(3).input).unwrap();
    let mut broken = input.clone();
    broken[60] ^= 0xff;
    std::fs::write(paths(3).input, &broken).unwrap();
    std::fs::remove_file(paths(3).done).unwrap();
    match build_part(&jobdir, &job, 3, &worker()) {
        Err(JobError::PartInput { part, .. }) => assert_eq!(part, 3),
        other => panic!("{other:?}"),
    }
    match &job_status(&jobdir, &job, false).unwrap()[3] {
        PartState::Failed(e) => {
            assert_eq!((e.part, e.kind.as_str()), (3, "input"));
            assert!(e.message.contains("checksum"), "{}", e.message);
        }
        other => panic!("{other:?}"),
    }
    std::fs::write(paths(3).input, &input).unwrap();

    // Re-running every part rebuilds exactly the broken ones.
    let untouched = (4..n).map(|k| (k, mtime(k))).collect::<Vec<_>>();
    for k in 0..n {
        let outcome = build_part(&jobdir, &job, k, &worker()).unwrap();
        let rebuilt = matches!(outcome, PartOutcome::Built(_));
        assert_eq!(rebuilt, k <= 3, "part {k}: {outcome:?}");
    }
    for (k, t) in untouched {
        assert_eq!(mtime(k), t, "part {k} was rewritten");
    }
    assert!(!paths(3).error.exists(), "the error record is removed");
    assert!(
        (0..n).all(|k| !paths(k).running.exists()),
        "every run removed its running record"
    );
    merge_job(&jobdir, &job, &out).unwrap();
    assert_eq!(std::fs::read(&out).unwrap(), reference);
}

/// Every TetGen option of the plan reaches the job file and comes back
/// from it, so that parts built from the file are built as planned.
#[test]
fn the_plan_records_every_tetgen_option() {
    use tet_build::tetgen::{Optimization, TetgenOptions};
    let scene = knot_grid(1, 60, 8);
    let dir = tempfile::tempdir().unwrap();
    let tetgen = TetgenOptions {
        quality: Some(4.0),
        max_steiner: Some(5000),
        min_dihedral: Some(2.0),
        optimization: Some(Optimization {
            level: 3,
            scheme: 1,
        }),
        max_dihedral: Some(150.0),
        ..TetgenOptions::default()
    };
    let options = PlanOptions {
        parts: 2,
        seam: SeamOptions {
            tetgen: tetgen.clone(),
            ..SeamOptions::default()
        },
        ..PlanOptions::default()
    };
    plan_job(&scene, &options, dir.path()).unwrap();
    let b = JobManifest::load(dir.path()).unwrap().build;
    assert_eq!(
        (
            b.quality,
            b.max_steiner,
            b.min_dihedral,
            b.optimization,
            b.max_dihedral
        ),
        (
            tetgen.quality,
            tetgen.max_steiner,
            tetgen.min_dihedral,
            tetgen.optimization,
            tetgen.max_dihedral
        )
    );
}

/// A knot of 120 segments to plan in four parts, a temporary directory
/// and the job directory in it.
fn four_part_job() -> (
    tet_build::scene::Scene,
    tempfile::TempDir,
    std::path::PathBuf,
    PlanOptions,
) {
    let dir = tempfile::tempdir().unwrap();
    let jobdir = dir.path().join("job");
    let options = PlanOptions {
        parts: 4,
        ..PlanOptions::default()
    };
    (knot_grid(1, 120, 12), dir, jobdir, options)
}

/// A part TetGen is stuck on in a job (its worker hangs) fails after a
/// time scaled to its size, not the worker's ten minutes, and its error
/// record says moving its walls may cure it. Planning the job again into
/// its directory moves that part's walls, and a third plan keeps them (it
/// never goes back to the input that failed); every part is rebuilt
/// exactly when its input changed, and the merge is the single-process
/// build of the moved planes, byte for byte.
#[cfg(unix)]
#[test]
fn a_part_stuck_in_a_job_is_cured_by_planning_again() {
    use std::os::unix::fs::PermissionsExt;
    let (scene, dir, jobdir, options) = four_part_job();
    let job = plan_job(&scene, &options, &jobdir).unwrap();
    assert!(job.failed_inputs.is_empty());
    let n = job.parts.len();
    let stuck = 1;

    let script = dir.path().join("hangs.sh");
    std::fs::write(&script, "#!/bin/sh\nexec sleep 120\n").unwrap();
    std::fs::set_permissions(&script, std::fs::Permissions::from_mode(0o755)).unwrap();
    let hangs = Isolation::Worker(WorkerCommand {
        program: script,
        args: vec![],
        timeout: Some(Duration::from_secs(600)),
    });
    let start = std::time::Instant::now();
    let e = build_part(&jobdir, &job, stuck, &hangs).unwrap_err();
    let took = start.elapsed().as_secs_f64();
    assert!(took < 100.0, "{took} s: the stuck part ran to its end");
    assert!(e.walls_may_cure(), "{e}");
    for k in (0..n).filter(|&k| k != stuck) {
        build_part(&jobdir, &job, k, &worker()).unwrap();
    }
    let out = dir.path().join("job.tmesh");
    let (_, failed, _) = not_ready(merge_job(&jobdir, &job, &out).unwrap_err());
    assert_eq!(failed, vec![stuck]);
    match &job_status(&jobdir, &job, false).unwrap()[stuck] {
        PartState::Failed(e) => assert!(e.retry && e.kind == "build", "{e:?}"),
        other => panic!("{other:?}"),
    }

    // Planned again: the stuck part's input is gone, its walls moved.
    let again = plan_job(&scene, &options, &jobdir).unwrap();
    assert_eq!(again.parts.len(), n);
    assert_eq!(again.failed_inputs.len(), 1, "{:?}", again.failed_inputs);
    let failed_digest = &job.parts[stuck].input_digest;
    assert_eq!(&again.failed_inputs[0].input_digest, failed_digest);
    assert!(again.parts.iter().all(|p| &p.input_digest != failed_digest));
    assert_ne!(again.partition, job.partition);
    assert_eq!(JobManifest::load(&jobdir).unwrap(), again);
    // The old error record is an earlier plan's.
    assert!(matches!(
        job_status(&jobdir, &again, false).unwrap()[stuck],
        PartState::Missing
    ));
    for k in 0..n {
        let changed = again.parts[k].input_digest != job.parts[k].input_digest;
        let outcome = build_part(&jobdir, &again, k, &worker()).unwrap();
        assert_eq!(
            matches!(outcome, PartOutcome::Built(_)),
            changed,
            "part {k}: {outcome:?}"
        );
    }
    merge_job(&jobdir, &again, &out).unwrap();
    let tree = match &again.partition {
        tet_build::outofcore::job::manifest::Partition::Tree { tree, .. } => tree.cut_tree(),
        other => panic!("{other:?}"),
    };
    let local_out = dir.path().join("local.tmesh");
    let local_options = SeamOptions {
        isolation: worker(),
        ..SeamOptions::default()
    };
    build_tree_to_file(
        &scene,
        &tree,
        &local_options,
        &StreamOptions::new(&local_out),
    )
    .unwrap();
    assert_eq!(
        std::fs::read(&out).unwrap(),
        std::fs::read(&local_out).unwrap()
    );

    // Planned a third time: the same plan, nothing to build.
    let third = plan_job(&scene, &options, &jobdir).unwrap();
    assert_eq!(third, again);
    for k in 0..n {
        assert!(matches!(
            build_part(&jobdir, &third, k, &worker()).unwrap(),
            PartOutcome::Skipped(_)
        ));
    }
}

/// A part a job's TetGen fails on wherever its walls stand is planned,
/// after its walls moved twice, with its surface relaxed: its input file
/// says so (another input, so another digest), `build-part` builds it
/// with `-Y/2`, and the job merges. The worker here crashes on every
/// request with plain `-Y` (read from the request's first bytes) and is
/// the real worker otherwise; only `stuck` goes through it.
#[cfg(unix)]
#[test]
fn a_part_failing_wherever_its_walls_stand_is_planned_with_its_surface_relaxed() {
    use tet_build::outofcore::tree::MAX_PART_MOVES;
    let (scene, dir, jobdir, options) = four_part_job();
    let (script, _) =
        common::crashing_on_plain_y(dir.path(), env!("CARGO_BIN_EXE_tet-build-worker"));
    let no_y = Isolation::Worker(WorkerCommand {
        program: script,
        args: vec![],
        timeout: Some(Duration::from_secs(60)),
    });
    let stuck = 1;
    let mut job = plan_job(&scene, &options, &jobdir).unwrap();
    let n = job.parts.len();
    for k in (0..n).filter(|&k| k != stuck) {
        build_part(&jobdir, &job, k, &worker()).unwrap();
    }
    let mut digests = Vec::new();
    // As planned, then moved MAX_PART_MOVES times: each fails.
    for round in 0..=MAX_PART_MOVES {
        let record = &job.parts[stuck];
        assert!(!record.surface_relaxed, "round {round}");
        assert!(!digests.contains(&record.input_digest), "round {round}");
        digests.push(record.input_digest.clone());
        let e = build_part(&jobdir, &job, stuck, &no_y).unwrap_err();
        assert!(e.walls_may_cure(), "{e}");
        job = plan_job(&scene, &options, &jobdir).unwrap();
        assert_eq!(job.failed_inputs.len(), round + 1);
    }
    // Relaxed where its walls last stood: the input differs from the
    // last failed one by its flag alone.
    let record = &job.parts[stuck];
    assert!(record.surface_relaxed);
    assert!(!digests.contains(&record.input_digest));
    assert!(job.parts.iter().filter(|p| p.surface_relaxed).count() == 1);
    let last = std::fs::read(jobdir.join(&record.input)).unwrap();
    let (input, _) = tet_build::outofcore::job::part_input::decode(&last).unwrap();
    assert!(input.surface_relaxed);
    let (unflagged, sum) = tet_build::outofcore::job::part_input::encode(
        &tet_build::outofcore::job::part_input::PartInput {
            surface_relaxed: false,
            ..input
        },
    );
    assert_eq!(
        tet_build::outofcore::job::digest::format_digest(sum),
        *digests.last().unwrap()
    );
    assert_eq!(unflagged.len(), last.len());
    for k in 0..n {
        let isolation = if k == stuck { &no_y } else { &worker() };
        build_part(&jobdir, &job, k, isolation).unwrap();
    }
    let out = dir.path().join("job.tmesh");
    merge_job(&jobdir, &job, &out).unwrap();
    let mesh = tet_core::format::load(&out).unwrap();
    mesh.validate().unwrap();
    assert_eq!(
        tet_core::InputTriangles::of(&mesh).len(),
        scene.triangles.len()
    );
}
