"""Builders of bad input for the bad-input table: files, folders and ports made in a test's
temporary folder."""

from __future__ import annotations

import socket
from pathlib import Path

import mission
from mission.config.scenario import load_scenario
from mission.link.waypoints import HEADER

GOOD_ROW = "0\t1\t3\t16\t0\t0.1\t0\t0\t35.15\t136.96\t7.0\t1\n"


def plan_dir(tmp: Path, broken: str | None = None, content: str = "") -> Path:
    """A copy of the shipped plan, with one file replaced by ``content``."""
    source = Path(load_scenario("along").task.waypoints_dir)
    target = tmp / "plan"
    target.mkdir()
    for path in source.glob("*.waypoints"):
        text = content if path.stem == broken else path.read_text()
        (target / path.name).write_text(text)
    return target


def scenario_file(tmp: Path, body: str, name: str = "bad.yaml") -> Path:
    path = tmp / name
    path.write_text(f"extends: along\nname: bad\n{body}")
    return path


def key_file(tmp: Path, content: bytes) -> Path:
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


def study_file(tmp: Path, body: str = "") -> Path:
    path = tmp / "s.yaml"
    path.write_text(f"scenarios: [along]\nseeds: 1\n{body}")
    return path


def results(tmp: Path, *rows: str) -> Path:
    """A committed study's folder (``committed``) whose results.csv holds Along AC seed 0
    (the run of :func:`study_file`'s study) and ``rows``."""
    folder = tmp / "committed"
    folder.mkdir(exist_ok=True)
    lines = ["scenario,point,method,seed,control_cycles", "along,0,ac,0,500"]
    lines += [f"{row},500" for row in rows]
    (folder / "results.csv").write_text("\n".join(lines) + "\n")
    return folder


def raw_file(tmp: Path, text: str) -> Path:
    path = tmp / "raw.yaml"
    path.write_text(text)
    return path


def mesh_file(tmp: Path, content: bytes, name: str = "junk.stl") -> Path:
    """A scenario whose structure is the mesh file ``content`` alone, its multipath from
    geometry where the name says ``flat`` (a reflecting mesh)."""
    (tmp / name).write_bytes(content)
    reflecting = "zones: [], gnss: {multipath: geometry}, " if name.startswith("flat") else ""
    structure = f"structure: {{mesh_file: {name}, primitives: []}}"
    return scenario_file(tmp, f"world: {{{reflecting}{structure}}}\n")


def low_deck_scenario(tmp: Path) -> Path:
    """Along under a deck from 6.5 to 9 m (the default bridge's is 8-9 m), as an OBJ file,
    its work path moved below it to 5 m: the shipped plan's waypoints at 7 m lie inside."""
    import trimesh

    deck = trimesh.creation.box(bounds=[(-20.0, -5.0, 6.5), (20.0, 5.0, 9.0)])
    (tmp / "deck.obj").write_text(trimesh.exchange.obj.export_obj(deck))
    structure = "world: {structure: {mesh_file: deck.obj, primitives: []}}\n"
    return scenario_file(tmp, structure + "task: {work_waypoints_m: [[-12, -3, 5], [0, -3, 5]]}\n")


def wpl_args(tmp: Path, content: str) -> list[str]:
    plan = plan_dir(tmp, "work", content)
    return [*RUN, str(scenario_file(tmp, f"task: {{waypoints_dir: {plan.name}}}\n"))]


SHIPPED_PLAN = Path(mission.__file__).resolve().parent / "scenarios" / "plans" / "bridge"
HELD_SOCKETS: list[socket.socket] = []  # busy ports stay busy until the session ends


def wpl_rows(*altitudes: float, frame: int = 3, command: int = 16) -> str:
    """A waypoint file: home at the anchor, 7 m up, then one row per altitude there."""
    rows = [GOOD_ROW]
    for seq, altitude in enumerate(altitudes, start=1):
        rows.append(f"{seq}\t0\t{frame}\t{command}\t0\t0.1\t0\t0\t35.15\t136.96\t{altitude}\t1\n")
    return HEADER + "\n" + "".join(rows)


def plain_file(tmp: Path, name: str = "a-file") -> Path:
    path = tmp / name
    path.write_text("x")
    return path


def new_dir(tmp: Path, name: str) -> Path:
    path = tmp / name
    path.mkdir()
    return path


def busy_port() -> int:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    HELD_SOCKETS.append(sock)
    return sock.getsockname()[1]


def tlog_run(tmp: Path, content: bytes, summary: str | None = None) -> Path:
    run = new_dir(tmp, "run")
    (run / "gcs.tlog").write_bytes(content)
    if summary is not None:
        (run / "summary.json").write_text(summary)
    return run if summary is not None else run / "gcs.tlog"
