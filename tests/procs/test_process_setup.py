"""Per-process set-up shared by the vehicle, the ground station and its helper."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from mission.procs.math_threads import THREAD_VARIABLES, use_one_math_thread


@pytest.mark.slow
def test_freezing_the_start_up_heap_exempts_what_was_loaded_from_collection():
    code = (
        "import gc, numpy, pymavlink.dialects.v20.ardupilotmega\n"
        "from mission.procs.cli_common import freeze_startup_heap\n"
        "before = gc.get_freeze_count()\n"
        "freeze_startup_heap()\n"
        "print(before, gc.get_freeze_count())\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    before, after = map(int, out.stdout.split())
    assert before == 0
    assert after > 20_000  # the modules' objects, which full collections now skip


def test_one_math_thread_is_asked_for_unless_the_user_said_otherwise(monkeypatch):
    for name in THREAD_VARIABLES:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("MKL_NUM_THREADS", "4")
    use_one_math_thread()
    assert os.environ["OPENBLAS_NUM_THREADS"] == "1"
    assert os.environ["MKL_NUM_THREADS"] == "4"
