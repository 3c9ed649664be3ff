"""Study files: what they expand to, and one line naming the culprit for each bad one."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from mission.config.errors import InputError
from mission.studies.spec import load_study, shipped_studies_dir, shipped_study_names


def _write(tmp_path: Path, text: str, name: str = "study.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def test_points_are_each_listed_point_crossed_with_the_grid_in_order(tmp_path):
    spec = load_study(
        _write(
            tmp_path,
            """
            scenarios: [along]
            seeds: {start: 5, count: 3}
            grid:
              fusion.rho_threshold: [0.0, 0.5]
            points:
              - {}
              - {fusion.agreement: paper}
            """,
        )
    )
    assert spec.name == "study" and spec.methods == ("ac", "nac") and spec.seeds == (5, 6, 7)
    assert [p.as_dict() for p in spec.points] == [
        {"fusion.rho_threshold": 0.0},
        {"fusion.rho_threshold": 0.5},
        {"fusion.agreement": "paper", "fusion.rho_threshold": 0.0},
        {"fusion.agreement": "paper", "fusion.rho_threshold": 0.5},
    ]
    assert spec.swept_keys == ["fusion.rho_threshold", "fusion.agreement"]
    assert spec.size == 1 * 4 * 2 * 3


def test_a_scenario_path_is_relative_to_the_study_file(tmp_path):
    (tmp_path / "sub").mkdir()
    _write(tmp_path / "sub", "extends: along\nname: mine\n", "mine.yaml")
    spec = load_study(_write(tmp_path, "scenarios: [sub/mine.yaml, wall]\nseeds: [3]\n"))
    assert spec.scenarios == (str((tmp_path / "sub" / "mine.yaml").resolve()), "wall")


ONE_METHOD = {"ceiling": "the question is the deck's distance, not the method"}


def test_every_shipped_study_is_valid():
    root = Path(__file__).resolve().parents[2] / "mission" / "studies" / "shipped"
    assert shipped_studies_dir() == root
    names = shipped_study_names()
    assert names == sorted(p.stem for p in root.glob("*.yaml"))
    assert {"smoke", "table3", "fusion-leakage", "work-speed"} <= set(names)
    for path in root.glob("*.yaml"):
        spec = load_study(path)
        assert spec.name == path.stem
        if path.stem != "smoke":  # the studies of the report: at least 15 paired seeds
            assert len(spec.seeds) >= 15 and "ac" in spec.methods
            assert set(spec.methods) == {"ac", "nac"} or path.stem in ONE_METHOD, path.stem


GRID_WEIGHTS = ("gnss", "interval", "waypoint", "relative", "penalty")
BAD = [
    ("scenarios: [along]\nsedes: 3\n", "sedes: unknown key"),
    ("scenarios: [along]\nrealtime: 0\n", "realtime: must be in [0.1, 1000], got 0"),
    ("scenarios: [along]\nrealtime: 0.001\n", "realtime: must be in [0.1, 1000], got 0.001"),
    ("scenarios: [along]\nrealtime: true\n", "realtime: must be a speed-up (a number)"),
    ("scenarios: [along]\nrealtime: fast\n", "realtime: must be a speed-up (a number)"),
    ("seeds: 3\n", "scenarios: must be a non-empty list"),
    ("scenarios: [nowhere]\n", "scenarios[0]: no such scenario"),
    ("scenarios: [along]\nmethods: [ac, xyz]\n", "methods: 'xyz' is not one of ac, nac"),
    ("scenarios: [along]\nseeds: -1\n", "seeds: names no seed"),
    ("scenarios: [along]\nseeds: [1, 1]\n", "seeds: a seed appears twice"),
    ("scenarios: [along]\nseeds: [1.5]\n", "seeds: 1.5 is not a seed"),
    ("scenarios: [along]\nseeds: {start: 0}\n", "seeds: must be a count"),
    ("scenarios: [along]\ngrid: {fusion.rho_threshold: 0.5}\n", "grid.fusion.rho_threshold: must"),
    ("scenarios: [along]\npoints: [{}, {}]\n", "points: the same point appears twice"),
    ("scenarios: [along]\npoints: [3]\n", "points[0]: must map dotted keys"),
    (
        "scenarios: [along]\ngrid: {map.eta: [0.1]}\npoints: [{map.eta: 0.2}]\n",
        "points[0].map.eta: is also a grid key",
    ),
    (
        "scenarios: [along]\npoints: [{fusion.rho_thresold: 0.5}]\n",
        "point 0 (fusion.rho_thresold=0.5): fusion.rho_thresold: unknown key",
    ),
    (
        "scenarios: [along]\ngrid: {fusion.rho_threshold: [0.0, 2.0]}\n",
        "point 1 (fusion.rho_threshold=2.0): fusion.rho_threshold: must be in [-1, 1]",
    ),
    (
        "scenarios: [along]\npoints: [{fusion.agreement: most}]\n",
        "point 0 (fusion.agreement=most): fusion.agreement:",
    ),
    (
        "scenarios: [along]\npoints: [{fusion: 1, fusion.eta: 2}]\n",
        "point 0: fusion.eta: fusion is set as a value and as a mapping",
    ),
    ("scenarios: [along]\ntables: [table9]\n", "tables: 'table9' is not one of table3"),
    (
        "scenarios: [along]\ntables: [table3]\ngrid: {map.eta: [0.1, 0.2]}\n",
        "tables: Table 3 is for a study of one point",
    ),
    ("name: ../up\nscenarios: [along]\n", "name: must be a plain folder name"),
    (  # refused before a list of 10^12 seeds is made (11.7 GB and a MemoryError before)
        "scenarios: [along]\nseeds: 1000000000000\n",
        "seeds: 1000000000000 seeds; at most 1000000 runs in one study",
    ),
    (
        "scenarios: [along]\nseeds: {start: 5, count: 2000000}\n",
        "seeds: 2000000 seeds; at most 1000000",
    ),
    (  # and before a grid of 10^8 points is expanded
        "scenarios: [along]\ngrid: {"
        + ", ".join(f"control.w_{w}: {list(range(1, 11))}" for w in GRID_WEIGHTS)
        + ", map.eta: [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95]"
        + ", fusion.broad_sigma_m: [0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4]"
        + ", fusion.rho_threshold: [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]}\n",
        "grid: 100,000,000 points; at most 10,000 in one study",
    ),
    (  # a grid of 10^6 points (the runs' cap) took two minutes to check, saying nothing
        "scenarios: [along]\ngrid: {"
        + ", ".join(f"control.w_{w}: {list(range(1, 11))}" for w in GRID_WEIGHTS)
        + ", map.eta: [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95]}\n",
        "grid: 1,000,000 points; at most 10,000 in one study",
    ),
    ("[1, 2]\n", "the file must hold a mapping"),
]


@pytest.mark.parametrize(("text", "expected"), BAD, ids=[b[1][:40] for b in BAD])
def test_a_bad_study_file_is_one_line_naming_the_file_and_the_culprit(tmp_path, text, expected):
    path = _write(tmp_path, text)
    with pytest.raises(InputError) as caught:
        load_study(path)
    message = str(caught.value)
    assert "\n" not in message and message.startswith(str(path)), message
    assert expected in message, message


def test_a_missing_study_file_is_named(tmp_path):
    with pytest.raises(InputError, match="no such study file"):
        load_study(tmp_path / "nope.yaml")


def test_a_study_over_an_hour_is_announced_with_its_estimate(monkeypatch):
    import mission.studies.study as study
    from mission.procs.machine_speed import REFERENCE_LOOP_S
    from mission.studies.study import duration_note

    def unmeasured(repeats: int = 5) -> float:
        raise AssertionError("a small study measures nothing")

    monkeypatch.setattr(study, "python_loop_s", unmeasured)
    assert duration_note(60, 2) is None  # Table 3: minutes
    monkeypatch.setattr(study, "python_loop_s", lambda repeats=5: REFERENCE_LOOP_S)
    assert duration_note(1000, 2) is None  # 3,000 s: under the hour
    note = duration_note(1_000_000, 2)  # 6 CPU-s a run on 2 cores: 3e6 s
    assert note is not None and "about 34.7 days on 2 cores" in note
    assert "per core of the cluster" in duration_note(2000, None)


def test_a_points_faults_are_told_briefly_and_a_ramp_as_a_ramp():
    from mission.studies.spec import value_text

    assert value_text("faults", []) == "none"
    one = [{"at_s": 10, "vehicle": "support-1", "failure": "gps off", "duration_s": 30}]
    assert value_text("faults", one) == "support-1 gps off 10-40 s"
    ramp = [
        {
            "at_s": 10 + k,
            "vehicle": "support-1",
            "param": "SIM_GPS1_GLTCH_Z",
            "value": 0.1 * (k + 1),
            "duration_s": 1,
        }
        for k in range(5)
    ]
    assert value_text("faults", ramp) == "support-1 SIM_GPS1_GLTCH_Z 0.1 to 0.5 in 5 steps, 10-15 s"
    apart = [dict(fault, at_s=fault["at_s"] * 2) for fault in ramp]  # not back to back
    assert value_text("faults", apart).count(";") == 4


def test_a_study_of_many_points_says_so_before_it_checks_them(tmp_path):
    path = tmp_path / "many.yaml"
    path.write_text(
        "scenarios: [along]\ngrid: {control.w_gnss: "
        + str(list(range(1, 16)))
        + ", map.eta: "
        + str([round(0.05 * k, 2) for k in range(1, 16)])
        + "}\n"
    )
    said: list[str] = []
    spec = load_study(path, say=said.append)
    assert len(spec.points) == 225
    assert said == ["checking the scenario of each of 225 points (a few ms each)"]


def test_a_study_of_many_runs_or_a_long_file_says_so_before_the_slow_part(tmp_path):
    many = tmp_path / "many.yaml"
    many.write_text("scenarios: [along]\nmethods: [ac]\nseeds: 20000\n")
    said: list[str] = []
    load_study(many, say=said.append)
    assert said == ["20,000 runs: checking and planning them takes a while"]
    long = tmp_path / "long.yaml"
    long.write_text(
        "scenarios: [along]\nmethods: [ac]\nseeds: [" + ", ".join(map(str, range(200_000))) + "]\n"
    )
    said.clear()
    load_study(long, say=said.append)
    assert said[0].startswith(f"reading {long} (1.") and said[0].endswith(" MB)")


def test_a_shipped_study_is_named_as_a_scenario_is(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # outside the checkout: found in the package, not here
    assert load_study(Path("smoke")).source == shipped_studies_dir() / "smoke.yaml"
    (tmp_path / "smoke").write_text("scenarios: [wall]\nname: mine\n")
    assert load_study(Path("smoke")).name == "mine"  # a file of that name here comes first
    with pytest.raises(
        InputError, match=r"nosuch: no such study file or shipped study \(shipped: .*smoke"
    ):
        load_study(Path("nosuch"))
