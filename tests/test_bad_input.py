"""Bad input everywhere: each case gives one line naming the file (or flag), the field or line
and the problem, exit status 2, and leaves no output behind."""

from __future__ import annotations

import socket
from pathlib import Path

import pytest

import ground_station.cli as gcs_cli
import mission
import mission.cli as mission_cli
import vehicle_sim.cli as vehicle_cli
from mission.config.scenario import load_scenario
from mission.link.waypoints import HEADER

GOOD_ROW = "0\t1\t3\t16\t0\t0.1\t0\t0\t35.15\t136.96\t7.0\t1\n"


def _plan_dir(tmp: Path, broken: str | None = None, content: str = "") -> Path:
    """A copy of the shipped plan, with one file replaced by ``content``."""
    source = Path(load_scenario("along").task.waypoints_dir)
    target = tmp / "plan"
    target.mkdir()
    for path in source.glob("*.waypoints"):
        text = content if path.stem == broken else path.read_text()
        (target / path.name).write_text(text)
    return target


def _scenario(tmp: Path, body: str, name: str = "bad.yaml") -> Path:
    path = tmp / name
    path.write_text(f"extends: along\nname: bad\n{body}")
    return path


def _key(tmp: Path, content: bytes) -> Path:
    path = tmp / "link.key"
    path.write_bytes(content)
    return path


RUN = ["run"]
FAR_BOX = (
    "world: {structure: {primitives: [{name: x, min_m: [0, 0, 0], max_m: [1.0e+30, 1, 1]}]}}\n"
)
WIDE_WINDOW = "map: {voxel_size_m: 0.5}\ncontrol: {horizon_steps: 25}\n"
HUGE_WORKSPACE = "world: {workspace: {min_m: [-20000, -20000, 0], max_m: [20000, 20000, 100]}}\n"
RAISED_LIMIT = "map: {voxel_size_m: 0.01}\nlimits: {max_map_voxels: 100000000000}\n"
MANY_PARTICLES = (
    "fusion: {broad_particles: 1000000000000}\nlimits: {max_particles: 10000000000000}\n"
)
TWO_ZONES = (
    "world: {{zones: [{{name: {name}, min_m: [0, 0, 1], max_m: [1, 1, 2], offset_m: [1, 0, 0]}},"
    " {{name: {name}, min_m: [2, 0, 1], max_m: [3, 1, 2], offset_m: [1, 0, 0]}}]}}\n"
)
CASES = [
    # --- safety margins ----------------------------------------------------------------
    (
        "yaml-negative-margin",
        lambda t: [*RUN, str(_scenario(t, "control: {clearance_m: -1}\n"))],
        ["bad.yaml", "control.clearance_m", "must not be negative"],
    ),
    (
        "yaml-negative-radius",
        lambda t: [*RUN, str(_scenario(t, "vehicle: {radius_m: -0.1}\n"))],
        ["bad.yaml", "vehicle.radius_m", "must be positive"],
    ),
    (
        "yaml-separation-below-two-bodies",
        lambda t: [*RUN, str(_scenario(t, "control: {min_separation_m: 0.3}\n"))],
        ["bad.yaml", "control.min_separation_m", "two bodies' radii"],
    ),
    (
        "yaml-clearance-below-a-body",
        lambda t: [*RUN, str(_scenario(t, "control: {clearance_m: 0.1}\n"))],
        ["bad.yaml", "control.clearance_m", "a body's radius"],
    ),
    (
        "run-plan-breaks-separation",
        lambda t: [*RUN, str(_scenario(t, "control: {min_separation_m: 3.5}\n"))],
        ["support-1.waypoints", "item", "control.min_separation_m (3.5 m)"],
    ),
    (
        "run-plan-breaks-clearance",
        lambda t: [*RUN, str(_scenario(t, "control: {clearance_m: 1.5}\n"))],
        ["work.waypoints", "item", "control.clearance_m (1.5 m)"],
    ),
    # --- scenario YAML -----------------------------------------------------------------
    (
        "yaml-syntax",
        lambda t: [*RUN, str(_scenario(t, "control: {horizon_steps: [\n"))],
        ["bad.yaml"],
    ),
    ("yaml-not-a-mapping", lambda t: [*RUN, str(_raw(t, "- 1\n- 2\n"))], ["raw.yaml", "mapping"]),
    (
        "unknown-key",
        lambda t: [*RUN, str(_scenario(t, "control: {horizon: 5}\n"))],
        ["bad.yaml", "horizon"],
    ),
    (
        "wrong-type",
        lambda t: [*RUN, str(_scenario(t, "control: {horizon_steps: five}\n"))],
        ["bad.yaml", "horizon_steps"],
    ),
    (
        "negative-time",
        lambda t: [*RUN, str(_scenario(t, "control: {t_pred_s: -1.0}\n"))],
        ["bad.yaml", "t_pred_s", "positive"],
    ),
    (
        "bad-choice",
        lambda t: [*RUN, str(_scenario(t, "control: {los_penalty: nearest}\n"))],
        ["bad.yaml", "los_penalty"],
    ),
    (
        "zero-sigma-limit",
        lambda t: [*RUN, str(_scenario(t, "control: {support_max_sigma0_m: 0}\n"))],
        ["bad.yaml", "support_max_sigma0_m"],
    ),
    (
        "nan-number",
        lambda t: [*RUN, str(_scenario(t, "gnss: {sigma_uere_m: .nan}\n"))],
        ["bad.yaml", "sigma_uere_m"],
    ),
    (
        "bad-epoch",
        lambda t: [*RUN, str(_scenario(t, "run: {epoch_utc: yesterday}\n"))],
        ["bad.yaml", "epoch_utc"],
    ),
    (
        "extends-missing",
        lambda t: [*RUN, str(_raw(t, "extends: nowhere.yaml\nname: x\n"))],
        ["nowhere"],
    ),
    (
        "extends-itself",
        lambda t: [*RUN, str(_raw(t, "extends: raw.yaml\nname: x\n"))],
        ["raw.yaml"],
    ),
    (
        "mesh-missing",
        lambda t: [*RUN, str(_scenario(t, "world: {structure: {mesh_file: gone.stl}}\n"))],
        ["gone.stl"],
    ),
    (
        "mesh-garbage",
        lambda t: [*RUN, str(_mesh(t, b"\x00\x01not a mesh at all" * 3))],
        ["junk.stl"],
    ),
    (
        "mesh-no-faces",
        lambda t: [*RUN, str(_mesh(t, b"v 0 0 0\nv 1 0 0\n", "flat.obj"))],
        ["flat.obj"],
    ),
    # --- what a run would ask of the machine --------------------------------------------------
    (
        "yaml-voxel-tiny",
        lambda t: [*RUN, str(_scenario(t, "map: {voxel_size_m: 0.01}\n"))],
        ["map.voxel_size_m", "50 x 40 x 20 m", "limits.max_map_voxels"],
    ),
    (
        "yaml-workspace-huge",
        lambda t: [*RUN, str(_scenario(t, HUGE_WORKSPACE))],
        ["map.voxel_size_m", "40000 x 40000 x 100 m", "GB"],
    ),
    (
        "yaml-mpc-window",
        lambda t: [
            *RUN,
            str(_scenario(t, "map: {voxel_size_m: 0.5}\ncontrol: {horizon_steps: 25}\n")),
        ],
        ["map.voxel_size_m", "limits.max_mpc_window_voxels"],
    ),
    (
        "yaml-particles",
        lambda t: [*RUN, str(_scenario(t, "fusion: {broad_particles: 1000000}\n"))],
        ["fusion.broad_particles", "limits.max_particles"],
    ),
    (
        "yaml-horizon",
        lambda t: [*RUN, str(_scenario(t, "control: {horizon_steps: 500}\n"))],
        ["control.horizon_steps", "limits.max_horizon_steps"],
    ),
    (
        "yaml-cycles",
        lambda t: [*RUN, str(_scenario(t, "control: {t_cont_s: 0.0001}\n"))],
        ["control.t_cont_s", "limits.max_control_cycles"],
    ),
    (
        "yaml-memory",
        lambda t: [*RUN, str(_scenario(t, RAISED_LIMIT))],
        ["map.voxel_size_m", "limits.max_memory_fraction", "this machine"],
    ),
    (
        "yaml-particle-memory",
        lambda t: [*RUN, str(_scenario(t, MANY_PARTICLES))],
        ["fusion.broad_particles", "limits.max_memory_fraction", "this machine"],
    ),
    (
        "mesh-far-away",
        lambda t: [*RUN, str(_mesh(t, b"v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n", "far.obj"))],
        ["far.obj", "from the anchor"],
    ),
    (
        "yaml-box-far-away",
        lambda t: [*RUN, str(_scenario(t, FAR_BOX))],
        ["bad.yaml", "world.structure.primitives[0].max_m", "at most"],
    ),
    (
        "yaml-zone-name-newline",
        lambda t: [*RUN, str(_scenario(t, TWO_ZONES.format(name='"a\\nb"')))],
        ["bad.yaml", "duplicate zone name", "a\\nb"],
    ),
    (
        "yaml-key-newline",
        lambda t: [*RUN, str(_scenario(t, '"con\\ntrol": {}\n'))],
        ["bad.yaml", "con\\ntrol", "unknown key"],
    ),
    (
        "scenario-file-newline",
        lambda t: [*RUN, str(t / "bad\nname.yaml")],
        ["bad\\nname.yaml", "no such scenario file"],
    ),
    (
        "plan-dir-missing",
        lambda t: [*RUN, str(_scenario(t, "task: {waypoints_dir: nowhere}\n"))],
        ["nowhere"],
    ),
    # --- waypoint files ----------------------------------------------------------------
    ("wpl-header", lambda t: _wpl(t, "QGC WPL 100\n" + GOOD_ROW), ["work.waypoints", "line 1"]),
    ("wpl-empty", lambda t: _wpl(t, ""), ["work.waypoints"]),
    (
        "wpl-columns",
        lambda t: _wpl(t, HEADER + "\n" + GOOD_ROW + "2\t0\t3\n"),
        ["work.waypoints", "line 3"],
    ),
    (
        "wpl-not-a-number",
        lambda t: _wpl(t, HEADER + "\n" + GOOD_ROW.replace("35.15", "north")),
        ["work.waypoints", "line 2"],
    ),
    (
        "wpl-latitude",
        lambda t: _wpl(t, HEADER + "\n" + GOOD_ROW.replace("35.15", "135.15")),
        ["work.waypoints", "line 2"],
    ),
    ("wpl-home-only", lambda t: _wpl(t, _rows()), ["work.waypoints", "at least one waypoint"]),
    (
        "wpl-too-many",
        lambda t: _wpl(t, _rows(*[7.0] * 600)),
        ["work.waypoints", "mission_capacity"],
    ),
    ("wpl-unequal", lambda t: _wpl(t, _rows(7.0)), ["support-1.waypoints", "pair by index"]),
    ("wpl-frame", lambda t: _wpl(t, _rows(7.0, frame=1)), ["work.waypoints", "item 1", "frame"]),
    ("wpl-command", lambda t: _wpl(t, _rows(7.0, command=178)), ["item 1", "command 178"]),
    ("wpl-in-deck", lambda t: _wpl(t, _rows(8.5)), ["work.waypoints", "inside the structure"]),
    ("wpl-too-high", lambda t: _wpl(t, _rows(50.0)), ["work.waypoints", "outside the workspace"]),
    (
        "wpl-gcs-in-deck",
        lambda t: ["--waypoints", str(_plan_dir(t, "support-3", _rows(8.5)))],
        ["support-3.waypoints", "inside the structure"],
    ),
    (
        "wpl-gcs-file",
        lambda t: ["--waypoints", str(_plan_dir(t, "support-2", "garbage\n"))],
        ["support-2.waypoints", "line 1"],
    ),
    # --- command-line arguments --------------------------------------------------------
    ("run-method", lambda t: [*RUN, "--method", "best"], ["--method"]),
    ("run-speedup", lambda t: [*RUN, "--realtime", "--speedup", "0"], ["--speedup"]),
    ("run-link-loss", lambda t: [*RUN, "--link-loss", "1.5"], ["--link-loss"]),
    ("run-link-delay", lambda t: [*RUN, "--link-delay-ms", "-3"], ["--link-delay-ms"]),
    ("run-observer", lambda t: [*RUN, "--observer", "qgc"], ["--observer"]),
    ("batch-trials", lambda t: ["batch", "--trials", "0"], ["--trials"]),
    ("batch-jobs", lambda t: ["batch", "--jobs", "0"], ["--jobs"]),
    ("batch-speedup-alone", lambda t: ["batch", "--speedup", "10"], ["--speedup", "--realtime"]),
    ("batch-speedup-zero", lambda t: ["batch", "--realtime", "--speedup", "0"], ["--speedup"]),
    ("gcs-waypoints-dir", lambda t: ["--waypoints", str(t / "none")], ["--waypoints"]),
    ("analyze-no-tlog", lambda t: ["analyze", str(_dir(t, "empty"))], ["no gcs.tlog"]),
    ("batch-methods", lambda t: ["batch", "--methods", "ac,best"], ["--methods"]),
    ("world-at-nan", lambda t: ["world", "--at", "1", "2", "nan"], ["--at"]),
    ("world-plot-suffix", lambda t: ["world", "--plot", str(t / "out" / "w.jpg")], ["--plot"]),
    ("scenario-name", lambda t: [*RUN, "nowhere-scenario"], ["nowhere-scenario"]),
    ("gcs-vehicles", lambda t: ["--vehicles", "work=localhost"], ["--vehicles"]),
    ("vehicle-name", lambda t: ["--vehicle", "support-x"], ["support-x"]),
    ("vehicle-speedup", lambda t: ["--vehicle", "work", "--speedup", "-1"], ["--speedup"]),
    ("vehicle-socket-fd", lambda t: ["--vehicle", "work", "--socket-fd", "987"], ["--socket-fd"]),
    (
        "vehicle-socket-fd-port",
        lambda t: ["--vehicle", "work", "--socket-fd", "3", "--port", "14560"],
        ["--socket-fd", "--port"],
    ),
    # --- output locations ----------------------------------------------------------------
    ("run-out-is-file", lambda t: [*RUN, "--out", str(_file(t))], ["--out", "is a file"]),
    ("run-out-under-file", lambda t: [*RUN, "--out", str(_file(t) / "a")], ["--out", "under"]),
    ("run-out-unwritable", lambda t: [*RUN, "--out", "/proc/1/run"], ["--out", "cannot write"]),
    ("batch-out-is-file", lambda t: ["batch", "--out", str(_file(t))], ["--out", "is a file"]),
    ("plan-out-is-file", lambda t: ["plan", "--out", str(_file(t))], ["--out", "is a file"]),
    ("plan-out-package", lambda t: ["plan", "--out", str(SHIPPED_PLAN)], ["--out", "package"]),
    ("plan-plot-no-dir", lambda t: ["plan", "--plot", str(t / "x" / "p.png")], ["--plot"]),
    ("world-plot-is-dir", lambda t: ["world", "--plot", str(_dir(t, "w.png"))], ["--plot"]),
    ("gcs-out-is-file", lambda t: ["--out", str(_file(t))], ["--out", "is a file"]),
    ("gcs-tlog-no-dir", lambda t: ["--tlog", str(t / "x" / "g.tlog")], ["--tlog", "no directory"]),
    # --- numbers out of range ------------------------------------------------------------
    ("run-seed", lambda t: [*RUN, "--seed", "-1"], ["--seed", "negative"]),
    ("run-speedup-lockstep", lambda t: [*RUN, "--speedup", "0"], ["--speedup", "--realtime"]),
    ("run-speedup-high", lambda t: [*RUN, "--realtime", "--speedup", "5000"], ["--speedup"]),
    (
        "world-at-far",
        lambda t: ["world", "along", "--at", "1e300", "0", "0"],
        ["outside the workspace"],
    ),
    ("run-observer-host", lambda t: [*RUN, "--observer", "999.1.1.1:14550"], ["'999.1.1.1'"]),
    ("run-speedup-tiny", lambda t: [*RUN, "--realtime", "--speedup", "1e-9"], ["[0.1, 1000]"]),
    ("gcs-seed", lambda t: ["--seed", "-3"], ["--seed", "negative"]),
    ("gcs-base-port", lambda t: ["--base-port", "70000"], ["--base-port", "65535"]),
    ("gcs-base-port-top", lambda t: ["--base-port", "65534"], ["--base-port", "65537"]),
    ("vehicle-seed", lambda t: ["--vehicle", "work", "--seed", "-1"], ["--seed"]),
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
        ["--host"],
    ),
    (
        "vehicle-host-not-ours",
        lambda t: ["--vehicle", "support-1", "--port", "0", "--host", "192.0.2.1"],
        ["--host", "not this machine"],
    ),
    (
        "vehicle-port-busy",
        lambda t: ["--vehicle", "support-1", "--port", str(_busy_port())],
        ["--port", "cannot listen"],
    ),
    (
        "vehicle-truth-port-busy",
        lambda t: ["--vehicle", "support-1", "--port", "0", "--truth-port", str(_busy_port())],
        ["--truth-port", "cannot listen"],
    ),
    # --- mission analyze ---------------------------------------------------------------------
    (
        "analyze-empty-tlog",
        lambda t: ["analyze", str(_tlog(t, b"")), "--scenario", "along"],
        ["gcs.tlog", "empty"],
    ),
    (
        "analyze-random-tlog",
        lambda t: ["analyze", str(_tlog(t, bytes(range(256)) * 40)), "--scenario", "along"],
        ["gcs.tlog", "no control cycle"],
    ),
    (
        "analyze-bad-summary",
        lambda t: ["analyze", str(_tlog(t, b"x", summary="{not json"))],
        ["summary.json", "JSON"],
    ),
    (
        "analyze-summary-list",
        lambda t: ["analyze", str(_tlog(t, b"x", summary="[1, 2]"))],
        ["summary.json", "not a JSON object"],
    ),
    # --- mission study -------------------------------------------------------------------
    ("study-missing", lambda t: ["study", str(t / "none.yaml")], ["none.yaml", "no such study"]),
    (
        "study-unknown-key",
        lambda t: ["study", str(_study(t, "points: [{fusion.rho_thresold: 0.5}]\n"))],
        ["s.yaml", "fusion.rho_thresold", "unknown key"],
    ),
    (
        "study-bad-value",
        lambda t: ["study", str(_study(t, "grid: {map.eta: [0.3, 1.5]}\n"))],
        ["s.yaml", "point 1", "map.eta"],
    ),
    (
        "study-bad-plan",
        lambda t: ["study", str(_study(t, f"points: [{{task.waypoints_dir: {t}}}]\n"))],
        ["work.waypoints"],
    ),
    ("study-jobs", lambda t: ["study", str(_study(t)), "--jobs", "0"], ["--jobs"]),
    (
        "study-address-local",
        lambda t: ["study", str(_study(t)), "--address", "10.0.0.1:6379"],
        ["--address", "--engine ray"],
    ),
    (
        "study-ray-unreachable",  # Ray retries for minutes: refused before anything starts
        lambda t: ["study", str(_study(t)), "--engine", "ray", "--address", "127.0.0.1:1"],
        ["--address", "no Ray head answers at 127.0.0.1:1"],
    ),
    (
        "study-ray-address-form",
        lambda t: ["study", str(_study(t)), "--engine", "ray", "--address", "headnode"],
        ["--address", "is not HOST:PORT"],
    ),
    ("study-keep", lambda t: ["study", str(_study(t)), "--keep", "some"], ["--keep"]),
    ("batch-twice", lambda t: ["batch", "along", "along", "--trials", "1"], ["along twice"]),
    (
        "study-scenario-twice",
        lambda t: ["study", str(_raw(t, "scenarios: [wall, along, wall]\nseeds: 1\n"))],
        ["raw.yaml: scenarios: lists wall twice"],
    ),
    (
        "study-out-is-file",
        lambda t: ["study", str(_study(t)), "--out", str(_file(t))],
        ["--out", "is a file"],
    ),
    (
        "study-runs-under-file",
        lambda t: ["study", str(_study(t)), "--runs", str(_file(t) / "r")],
        ["--runs", "under"],
    ),
    # --- signing keys ------------------------------------------------------------------
    ("key-missing", lambda t: [*RUN, "--signing-key", str(t / "none.key")], ["none.key"]),
    (
        "key-short",
        lambda t: [*RUN, "--signing-key", str(_key(t, b"0" * 31))],
        ["link.key", "31 bytes"],
    ),
    (
        "key-not-hex",
        lambda t: [*RUN, "--signing-key", str(_key(t, b"g" * 64))],
        ["link.key", "hexadecimal"],
    ),
    (
        "key-vehicle",
        lambda t: ["--vehicle", "work", "--signing-key", str(_key(t, b"1" * 33))],
        ["link.key"],
    ),
]


def _study(tmp: Path, body: str = "") -> Path:
    path = tmp / "s.yaml"
    path.write_text(f"scenarios: [along]\nseeds: 1\n{body}")
    return path


def _raw(tmp: Path, text: str) -> Path:
    path = tmp / "raw.yaml"
    path.write_text(text)
    return path


def _mesh(tmp: Path, content: bytes, name: str = "junk.stl") -> Path:
    (tmp / name).write_bytes(content)
    return _scenario(tmp, f"world: {{structure: {{mesh_file: {name}, primitives: []}}}}\n")


def _wpl(tmp: Path, content: str) -> list[str]:
    plan = _plan_dir(tmp, "work", content)
    return [*RUN, str(_scenario(tmp, f"task: {{waypoints_dir: {plan.name}}}\n"))]


SHIPPED_PLAN = Path(mission.__file__).resolve().parent / "scenarios" / "plans" / "bridge"
_HELD_SOCKETS: list[socket.socket] = []  # busy ports stay busy until the session ends


def _rows(*altitudes: float, frame: int = 3, command: int = 16) -> str:
    """A waypoint file: home at the anchor, 7 m up, then one row per altitude there."""
    rows = [GOOD_ROW]
    for seq, altitude in enumerate(altitudes, start=1):
        rows.append(f"{seq}\t0\t{frame}\t{command}\t0\t0.1\t0\t0\t35.15\t136.96\t{altitude}\t1\n")
    return HEADER + "\n" + "".join(rows)


def _file(tmp: Path) -> Path:
    path = tmp / "a-file"
    path.write_text("x")
    return path


def _dir(tmp: Path, name: str) -> Path:
    path = tmp / name
    path.mkdir()
    return path


def _busy_port() -> int:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    _HELD_SOCKETS.append(sock)
    return sock.getsockname()[1]


def _tlog(tmp: Path, content: bytes, summary: str | None = None) -> Path:
    run = _dir(tmp, "run")
    (run / "gcs.tlog").write_bytes(content)
    if summary is not None:
        (run / "summary.json").write_text(summary)
    return run if summary is not None else run / "gcs.tlog"


def _entry(case: str):
    if case.startswith(("gcs-", "wpl-gcs")):
        return gcs_cli.entry_point
    if case.startswith(("vehicle-", "key-vehicle")):
        return vehicle_cli.entry_point
    return mission_cli.entry_point


def test_the_table_covers_every_kind_of_input():
    assert len(CASES) >= 60
    kinds = {c[0].split("-")[0] for c in CASES}
    kinds_wanted = {"yaml", "wpl", "mesh", "run", "key", "gcs", "vehicle", "analyze", "plan"}
    assert kinds_wanted | {"study"} <= kinds


@pytest.mark.parametrize(("case", "argv", "expected"), CASES, ids=[c[0] for c in CASES])
def test_bad_input_gives_one_line_status_2_and_no_output(
    case, argv, expected, tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)  # default output directories would land here
    arguments = argv(tmp_path)
    (tmp_path / "out").mkdir()
    before = sorted(p.name for p in tmp_path.rglob("*"))
    try:
        status = _entry(case)(arguments)
    except SystemExit as exit_:  # argparse usage errors
        status = exit_.code
    err = capsys.readouterr().err
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for text in expected:
        assert text in lines[0], lines[0]
    assert "Traceback" not in err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before, "no output left behind"
