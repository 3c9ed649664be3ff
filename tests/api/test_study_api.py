"""``mission.study``: a study from Python is the command line's study (a run made by one is
found done by the other), its results a DataFrame; bad arguments raise before any run."""

from __future__ import annotations

import pytest
import yaml

import mission
from mission.config.errors import InputError
from tests.processes import mission as mission_command

MINI = {
    "name": "api-mini",
    "scenarios": ["along"],
    "methods": ["ac", "nac"],
    "seeds": 1,
    "points": [{"run.timeout_s": 10.0}],
}


@pytest.mark.slow
def test_a_python_study_is_the_command_lines_and_resumes_there(tmp_path):
    out = tmp_path / "out"
    made = mission.study(MINI, out=out, jobs=2, keep="logs")
    assert (made.finished, made.skipped, made.failed) == (2, 0, 0)
    results = made.results
    assert list(results["method"]) == ["ac", "nac"] and (results["control_cycles"] == 20).all()
    assert made.report.is_file()
    assert made.run("along", "nac", 0).summary.control_cycles == 20
    study_file = tmp_path / "api-mini.yaml"
    study_file.write_text(yaml.safe_dump(MINI))
    again = mission_command("study", str(study_file), "--out", str(out), "--keep", "logs")
    assert again.returncode == 0, again.stderr
    assert "0 runs finished, 2 already done" in again.stdout


@pytest.mark.parametrize(
    ("spec", "kwargs", "named"),
    [
        ({**MINI, "seeds": 0}, {}, "seeds"),
        ({**MINI, "scenarios": ["nowhere"]}, {}, "study(): scenarios[0]"),
        ({**MINI, "colour": "red"}, {}, "colour"),
        (MINI, {"jobs": 0}, "study(): jobs"),
        (MINI, {"engine": "spark"}, "study(): engine"),
        (MINI, {"keep": "some"}, "study(): keep"),
        (MINI, {"address": "10.0.0.1:6379"}, "study(): address"),
    ],
)
def test_bad_arguments_raise_before_any_run(tmp_path, spec, kwargs, named):
    with pytest.raises(InputError) as raised:
        mission.study(spec, out=tmp_path / "never", **kwargs)
    assert named in str(raised.value)
    assert not (tmp_path / "never").exists()
