"""The README's two commands: the main job installs the project alone (the test extra pulls
MAVProxy and its GUI stack), and CI runs exactly the README's test command."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _two_commands() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Two commands", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"```bash\n(.*?)```", section, re.S).group(1)
    return [line.split("#", 1)[0].strip() for line in block.strip().splitlines()]


def test_the_main_job_installs_the_project_alone_and_runs_the_default_scenario():
    main_job, _ = _two_commands()
    install, run = (shlex.split(part) for part in main_job.split("&&"))
    assert install == ["python", "-m", "pip", "install", "-e", "."]
    assert run == ["python", "-m", "mission", "run"]


def test_ci_runs_the_readmes_test_command():
    _, tests = _two_commands()
    install, run = (shlex.split(part) for part in tests.split("&&"))
    assert install == ["python", "-m", "pip", "install", "-e", ".[test]"]
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert "\"$PYTHON\" -m pip install --quiet --disable-pip-version-check -e '.[test]'" in ci
    assert '"$PYTHON" ' + " ".join(run[1:]) in ci


def test_ci_runs_the_determinism_tests_again_with_narrowed_kernels():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    readme_tests = ci.index('"$PYTHON" -m pytest -q')
    again = [line for line in ci[readme_tests:] if "-m determinism" in line]
    assert again and again[0].startswith("env $NARROWED "), again
