"""Bad command lines: arguments, output locations, numbers out of range, analyze, study, view
and signing keys (id, argv builder, texts the one error line must hold)."""

from __future__ import annotations

from pathlib import Path

from tests.bad_input.builders import (
    RUN,
    SHIPPED_PLAN,
    busy_port,
    key_file,
    new_dir,
    plain_file,
    raw_file,
    results,
    scenario_file,
    study_file,
    tlog_run,
)

SUMMARY_ALONG = '{"scenario": "along"}'

COMMAND_CASES = [
    # --- command-line arguments --------------------------------------------------------
    ("run-method", lambda t: [*RUN, "--method", "best"], ["--method", "invalid choice: 'best'"]),
    (
        "run-speedup",
        lambda t: [*RUN, "--realtime", "--speedup", "0"],
        ["--speedup", "must be in [0.1, 1000], got 0"],
    ),
    (
        "run-link-loss",
        lambda t: [*RUN, "--link-loss", "1.5"],
        ["--link-loss", "must be in [0, 1), got 1.5"],
    ),
    (
        "run-link-delay",
        lambda t: [*RUN, "--link-delay-ms", "-3"],
        ["--link-delay-ms", "must be in [0, 10000], got -3.0"],
    ),
    (
        "run-observer",
        lambda t: [*RUN, "--observer", "qgc"],
        ["--observer", "address must look like HOST:PORT, got 'qgc'"],
    ),
    ("run-stall", lambda t: [*RUN, "--stall-s", "-5"], ["--stall-s", ">= 0"]),
    (  # an earlier run's folder is not written over without a word
        "run-out-holds-a-run",
        lambda t: [*RUN, "--out", str(tlog_run(t, b"\xfe" * 40, "{}"))],
        ["--out", "holds a run", "--force"],
    ),
    (
        "batch-trials",
        lambda t: ["batch", "--trials", "0"],
        ["--trials", "must be in [1, 1000], got 0"],
    ),
    (  # a bad scenario named as the file it is, not as "command line: point 0 (defaults)"
        "batch-bad-scenario",
        lambda t: ["batch", str(scenario_file(t, "control: {horizon_steps: -1}\n"))],
        ["bad.yaml: control.horizon_steps", "must be at least 1"],
    ),
    ("batch-jobs", lambda t: ["batch", "--jobs", "0"], ["--jobs", "must be in [1, 256], got 0"]),
    ("batch-speedup-alone", lambda t: ["batch", "--speedup", "10"], ["--speedup", "--realtime"]),
    (
        "batch-speedup-zero",
        lambda t: ["batch", "--realtime", "--speedup", "0"],
        ["--speedup", "must be in [0.1, 1000], got 0"],
    ),
    (
        "gcs-waypoints-dir",
        lambda t: ["--waypoints", str(t / "none")],
        ["--waypoints", "is not a directory"],
    ),
    (
        "analyze-no-tlog",
        lambda t: ["analyze", str(new_dir(t, "empty"))],
        ["no gcs.tlog", "give a run directory or a tlog"],
    ),
    (
        "batch-methods",
        lambda t: ["batch", "--methods", "ac,best"],
        ["--methods", "expected ac and/or nac"],
    ),
    (
        "world-at-nan",
        lambda t: ["world", "--at", "1", "2", "nan"],
        ["--at", "expects three finite numbers"],
    ),
    (
        "world-plot-suffix",
        lambda t: ["world", "--plot", str(t / "out" / "w.jpg")],
        ["--plot", "must end in .png or .pdf or .svg"],
    ),
    (
        "responses-plot-suffix",  # mission vehicle (a "vehicle-" case is vehicle_sim's)
        lambda t: ["vehicle", "--plot", str(t / "out" / "v.jpg")],
        ["--plot", "must end in .png or .pdf or .svg"],
    ),
    (
        "scenario-name",
        lambda t: [*RUN, "nowhere-scenario"],
        ["nowhere-scenario", "no such scenario (embedded ones:"],
    ),
    (
        "gcs-vehicles",
        lambda t: ["--vehicles", "work=localhost"],
        ["--vehicles", "must look like HOST:PORT, got 'localhost'"],
    ),
    (
        "vehicle-name",
        lambda t: ["--vehicle", "support-x"],
        ["support-x", "must be 'work' or 'support-N'"],
    ),
    (
        "vehicle-speedup",
        lambda t: ["--vehicle", "work", "--speedup", "-1"],
        ["--speedup", "must be in [0.1, 1000], got -1"],
    ),
    (
        "vehicle-socket-fd",
        lambda t: ["--vehicle", "work", "--socket-fd", "987"],
        ["--socket-fd", "987 is not an open socket"],
    ),
    (
        "vehicle-socket-fd-port",
        lambda t: ["--vehicle", "work", "--socket-fd", "3", "--port", "14560"],
        ["--socket-fd", "--port"],
    ),
    # --- output locations ----------------------------------------------------------------
    ("run-out-is-file", lambda t: [*RUN, "--out", str(plain_file(t))], ["--out", "is a file"]),
    ("run-out-under-file", lambda t: [*RUN, "--out", str(plain_file(t) / "a")], ["--out", "under"]),
    ("run-out-unwritable", lambda t: [*RUN, "--out", "/proc/1/run"], ["--out", "cannot write"]),
    ("batch-out-is-file", lambda t: ["batch", "--out", str(plain_file(t))], ["--out", "is a file"]),
    ("plan-out-is-file", lambda t: ["plan", "--out", str(plain_file(t))], ["--out", "is a file"]),
    ("plan-out-package", lambda t: ["plan", "--out", str(SHIPPED_PLAN)], ["--out", "package"]),
    (
        "plan-plot-no-dir",
        lambda t: ["plan", "--plot", str(t / "x" / "p.png")],
        ["--plot", "no directory"],
    ),
    (
        "world-plot-is-dir",
        lambda t: ["world", "--plot", str(new_dir(t, "w.png"))],
        ["--plot", "is a directory, not a file"],
    ),
    ("gcs-out-is-file", lambda t: ["--out", str(plain_file(t))], ["--out", "is a file"]),
    ("gcs-tlog-no-dir", lambda t: ["--tlog", str(t / "x" / "g.tlog")], ["--tlog", "no directory"]),
    # --- numbers out of range ------------------------------------------------------------
    ("run-seed", lambda t: [*RUN, "--seed", "-1"], ["--seed", "negative"]),
    ("run-speedup-lockstep", lambda t: [*RUN, "--speedup", "0"], ["--speedup", "--realtime"]),
    (
        "run-speedup-high",
        lambda t: [*RUN, "--realtime", "--speedup", "5000"],
        ["--speedup", "must be in [0.1, 1000], got 5000"],
    ),
    (
        "world-at-far",
        lambda t: ["world", "along", "--at", "1e300", "0", "0"],
        ["outside the workspace", "--at"],
    ),
    (
        "run-observer-host",
        lambda t: [*RUN, "--observer", "999.1.1.1:14550"],
        ["'999.1.1.1'", "is not an IPv4 address or a known host"],
    ),
    (
        "run-speedup-tiny",
        lambda t: [*RUN, "--realtime", "--speedup", "1e-9"],
        ["[0.1, 1000]", "--speedup"],
    ),
    ("gcs-seed", lambda t: ["--seed", "-3"], ["--seed", "negative"]),
    ("gcs-base-port", lambda t: ["--base-port", "70000"], ["--base-port", "65535"]),
    ("gcs-base-port-top", lambda t: ["--base-port", "65534"], ["--base-port", "65537"]),
    (
        "vehicle-seed",
        lambda t: ["--vehicle", "work", "--seed", "-1"],
        ["--seed", "must not be negative, got -1"],
    ),
    (
        "vehicle-home-inside",
        lambda t: ["--vehicle", "work", "--home", "0", "0", "8.5"],
        ["--home", "inside the structure"],
    ),
    (
        "vehicle-home-outside",
        lambda t: ["--vehicle", "work", "--home", "0", "0", "50"],
        ["--home", "outside the workspace"],
    ),
    # --- the flag at fault named ---------------------------------------------------------
    (
        "vehicle-host-unknown",
        lambda t: ["--vehicle", "support-1", "--port", "0", "--host", "nosuchhost.invalid"],
        ["--host", "is not an address"],
    ),
    (
        "vehicle-host-not-ours",
        lambda t: ["--vehicle", "support-1", "--port", "0", "--host", "192.0.2.1"],
        ["--host", "not this machine"],
    ),
    (
        "vehicle-port-busy",
        lambda t: ["--vehicle", "support-1", "--port", str(busy_port())],
        ["--port", "cannot listen"],
    ),
    (
        "vehicle-truth-port-busy",
        lambda t: ["--vehicle", "support-1", "--port", "0", "--truth-port", str(busy_port())],
        ["--truth-port", "cannot listen"],
    ),
    # --- mission analyze ---------------------------------------------------------------------
    (
        "analyze-empty-tlog",
        lambda t: ["analyze", str(tlog_run(t, b"")), "--scenario", "along"],
        ["gcs.tlog", "empty"],
    ),
    (
        "analyze-random-tlog",
        lambda t: ["analyze", str(tlog_run(t, bytes(range(256)) * 40)), "--scenario", "along"],
        ["gcs.tlog", "no control cycle"],
    ),
    (
        "analyze-bad-summary",
        lambda t: ["analyze", str(tlog_run(t, b"x", summary="{not json"))],
        ["summary.json", "JSON"],
    ),
    (
        "analyze-summary-list",
        lambda t: ["analyze", str(tlog_run(t, b"x", summary="[1, 2]"))],
        ["summary.json", "not a JSON object"],
    ),
    (
        "analyze-another-flight",  # --scenario may judge a run otherwise, not fly it otherwise
        lambda t: [
            "analyze",
            str(tlog_run(t, b"x", summary=SUMMARY_ALONG)),
            "--scenario",
            "twozone-4",
        ],
        ["--scenario", "task.supports", "the run did not fly it"],
    ),
    (
        "analyze-records-a-folder",
        lambda t: ["analyze", str(_with_records_folder(tlog_run(t, b"x", summary=SUMMARY_ALONG)))],
        ["records.jsonl", "not a regular file"],
    ),
    (
        "plot-onto-a-dangling-link",
        lambda t: ["world", "along", "--plot", str(_dangling_link(t, "w.png"))],
        ["--plot", "a link to a missing file"],
    ),
    # --- mission study -------------------------------------------------------------------
    ("study-missing", lambda t: ["study", str(t / "none.yaml")], ["none.yaml", "no such study"]),
    (
        "study-unknown-key",
        lambda t: ["study", str(study_file(t, "points: [{fusion.rho_thresold: 0.5}]\n"))],
        ["s.yaml", "fusion.rho_thresold", "unknown key"],
    ),
    (
        "study-bad-value",
        lambda t: ["study", str(study_file(t, "grid: {map.eta: [0.3, 1.5]}\n"))],
        ["s.yaml", "point 1", "map.eta"],
    ),
    (
        "study-bad-plan",
        lambda t: ["study", str(study_file(t, f"points: [{{task.waypoints_dir: {t}}}]\n"))],
        ["work.waypoints", "no waypoint file for work"],
    ),
    (
        "study-jobs",
        lambda t: ["study", str(study_file(t)), "--jobs", "0"],
        ["--jobs", "must be in [1, 256], got 0"],
    ),
    (
        "study-address-local",
        lambda t: ["study", str(study_file(t)), "--address", "10.0.0.1:6379"],
        ["--address", "--engine ray"],
    ),
    (
        "study-ray-unreachable",  # Ray retries for minutes: refused before anything starts
        lambda t: ["study", str(study_file(t)), "--engine", "ray", "--address", "127.0.0.1:1"],
        ["--address", "no Ray head answers at 127.0.0.1:1"],
    ),
    (
        "study-ray-address-form",
        lambda t: ["study", str(study_file(t)), "--engine", "ray", "--address", "headnode"],
        ["--address", "is not HOST:PORT"],
    ),
    (
        "study-keep",
        lambda t: ["study", str(study_file(t)), "--keep", "some"],
        ["--keep", "invalid choice: 'some'"],
    ),
    (
        "batch-twice",
        lambda t: ["batch", "along", "along", "--trials", "1"],
        ["along twice", "SCENARIO"],
    ),
    (
        "study-scenario-twice",
        lambda t: ["study", str(raw_file(t, "scenarios: [wall, along, wall]\nseeds: 1\n"))],
        ["raw.yaml: scenarios: lists wall twice", "raw.yaml"],
    ),
    (
        "study-out-is-file",
        lambda t: ["study", str(study_file(t)), "--out", str(plain_file(t))],
        ["--out", "is a file"],
    ),
    (
        "study-results-is-folder",
        lambda t: [
            "study",
            str(study_file(t)),
            "--out",
            str(new_dir(new_dir(t, "o"), "results.csv").parent),
        ],
        ["results.csv is a directory", "--out"],
    ),
    (
        "study-runs-is-file",
        lambda t: [
            "study",
            str(study_file(t)),
            "--out",
            str(plain_file(new_dir(t, "o"), "runs").parent),
        ],
        ["runs is a file", "--out"],
    ),
    (
        "run-out-proc",
        lambda t: [*RUN, "--out", "/proc/mission-run"],
        ["cannot write in '/proc'", "--out"],
    ),
    (
        "study-runs-under-file",
        lambda t: ["study", str(study_file(t)), "--runs", str(plain_file(t) / "r")],
        ["--runs", "under"],
    ),
    # --- mission study --verify --------------------------------------------------------
    (
        "study-verify-zero",
        lambda t: ["study", str(study_file(t)), "--verify", "0", "--against", str(results(t))],
        ["--verify", ">= 1"],
    ),
    (
        "study-verify-alone",
        lambda t: ["study", str(study_file(t)), "--verify", "2"],
        ["--against", "--verify needs the committed study's DIR"],
    ),
    (
        "study-against-alone",
        lambda t: ["study", str(study_file(t)), "--against", str(results(t))],
        ["--against", "is for --verify"],
    ),
    (
        "study-draw-seed-alone",
        lambda t: ["study", str(study_file(t)), "--draw-seed", "3"],
        ["--draw-seed", "is for --verify N"],
    ),
    (
        "study-historical-alone",
        lambda t: ["study", str(study_file(t)), "--historical", "old code"],
        ["--historical", "--report-only"],
    ),
    (
        "study-against-empty",
        lambda t: ["study", str(study_file(t)), "--verify", "1", "--against", str(new_dir(t, "c"))],
        ["--against", "no results.csv"],
    ),
    (
        "study-against-foreign-row",
        lambda t: [
            "study",
            str(study_file(t)),
            "--verify",
            "all",
            "--against",
            str(results(t, "wall,0,ac,0")),
        ],
        ["results.csv", "line 3", "wall point 0 ac seed 0 is not a run"],
    ),
    (
        "study-verify-into-against",
        lambda t: [
            "study",
            str(study_file(t)),
            "--verify",
            "1",
            "--against",
            str(results(t)),
            "--out",
            str(t / "committed"),
        ],
        ["--out", "must not be --against"],
    ),
    (
        "study-historical-blank",
        lambda t: [
            "study",
            str(study_file(t)),
            "--report-only",
            "--out",
            str(results(t)),
            "--historical",
            " ",
        ],
        ["--historical", "say why"],
    ),
    # --- signing keys ------------------------------------------------------------------
    (
        "key-missing",
        lambda t: [*RUN, "--signing-key", str(t / "none.key")],
        ["none.key", "cannot read"],
    ),
    (
        "key-short",
        lambda t: [*RUN, "--signing-key", str(key_file(t, b"0" * 31))],
        ["link.key", "31 bytes"],
    ),
    (
        "key-not-hex",
        lambda t: [*RUN, "--signing-key", str(key_file(t, b"g" * 64))],
        ["link.key", "hexadecimal"],
    ),
    (
        "key-vehicle",
        lambda t: ["--vehicle", "work", "--signing-key", str(key_file(t, b"1" * 33))],
        ["link.key", "expected 32 raw bytes or 64 hex digits"],
    ),
]


def _with_records_folder(run: Path) -> Path:
    (run / "records.jsonl").mkdir()
    return run


def _dangling_link(tmp: Path, name: str) -> Path:
    link = tmp / name
    link.symlink_to(tmp / "gone" / name)
    return link
