"""Per-process set-up shared by the vehicle, the ground station and its helper."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from mission.procs import numerics
from mission.procs.numerics import (
    NUMPY_VARIABLES,
    PINNED_KERNELS,
    THREAD_VARIABLES,
    prepare_numerics,
)


@pytest.mark.slow
def test_freezing_the_start_up_heap_exempts_what_was_loaded_from_collection():
    code = (
        "import gc, numpy, pymavlink.dialects.v20.ardupilotmega\n"
        "from mission.procs.process_life import freeze_startup_heap\n"
        "before = gc.get_freeze_count()\n"
        "freeze_startup_heap()\n"
        "print(before, gc.get_freeze_count())\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    before, after = map(int, out.stdout.split())
    assert before == 0
    assert after > 20_000  # the modules' objects, which full collections now skip


def _cpuinfo(tmp_path: Path, flags: str) -> str:
    path = tmp_path / "cpuinfo"
    path.write_text(f"processor\t: 0\nmodel name\t: Test CPU\nflags\t\t: {flags}\n")
    return str(path)


HASWELL_FLAGS = "fpu sse sse2 ssse3 sse4_1 sse4_2 avx avx2 fma f16c bmi1 bmi2 abm movbe"


@pytest.fixture
def clean_environment(monkeypatch):
    """No numerical variable set: as a fresh shell."""
    names = (*THREAD_VARIABLES, *NUMPY_VARIABLES, *PINNED_KERNELS)
    for name in names:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr(numerics.sys, "platform", "linux")
    monkeypatch.setattr(numerics.platform, "machine", lambda: "x86_64")
    return monkeypatch


def test_one_math_thread_is_asked_for_unless_the_user_said_otherwise(clean_environment, tmp_path):
    clean_environment.setenv("MKL_NUM_THREADS", "4")
    prepare_numerics(_cpuinfo(tmp_path, HASWELL_FLAGS))
    assert os.environ["OPENBLAS_NUM_THREADS"] == "1"
    assert os.environ["MKL_NUM_THREADS"] == "4"


def test_a_machine_with_avx2_and_fma_gets_the_pinned_kernels(clean_environment, tmp_path):
    prepare_numerics(_cpuinfo(tmp_path, HASWELL_FLAGS + " avx512f avx512bw"))
    assert os.environ["NPY_ENABLE_CPU_FEATURES"] == "X86_V3"
    assert os.environ["OPENBLAS_CORETYPE"] == "Haswell"
    assert os.environ["MKL_CBWR"] == "AVX2"


@pytest.mark.parametrize("missing", ["avx2", "fma", "movbe"])
def test_a_machine_without_the_pinned_kernels_instructions_is_left_alone(
    clean_environment, tmp_path, missing
):
    flags = " ".join(flag for flag in HASWELL_FLAGS.split() if flag != missing)
    prepare_numerics(_cpuinfo(tmp_path, flags))
    assert not any(os.environ.get(name) for name in (*NUMPY_VARIABLES, *PINNED_KERNELS))
    assert os.environ["OPENBLAS_NUM_THREADS"] == "1"  # the threads are still set


def test_arm_and_a_missing_cpuinfo_pin_nothing(clean_environment, tmp_path):
    assert numerics.can_pin(_cpuinfo(tmp_path, HASWELL_FLAGS))
    assert not numerics.can_pin(str(tmp_path / "absent"))
    clean_environment.setattr(numerics.platform, "machine", lambda: "aarch64")
    assert not numerics.can_pin(_cpuinfo(tmp_path, HASWELL_FLAGS))


def test_the_users_kernel_settings_are_kept(clean_environment, tmp_path):
    clean_environment.setenv("NPY_DISABLE_CPU_FEATURES", "X86_V3 X86_V4")
    clean_environment.setenv("OPENBLAS_CORETYPE", "Sandybridge")
    prepare_numerics(_cpuinfo(tmp_path, HASWELL_FLAGS))
    assert "NPY_ENABLE_CPU_FEATURES" not in os.environ  # numpy refuses both at once
    assert os.environ["OPENBLAS_CORETYPE"] == "Sandybridge"
    assert os.environ["MKL_CBWR"] == "AVX2"


@pytest.mark.slow
def test_a_started_process_computes_with_the_pinned_kernels():
    """Through the real entry point: numpy's dispatch and OpenBLAS's core as pinned, on a
    machine that can run them (elsewhere: nothing pinned, and it says so)."""
    code = (
        "import json, sys\n"
        "from mission.__main__ import prepare_numerics\n"
        "prepare_numerics()\n"
        "from mission.procs.numerics import numerics_in_use\n"
        "print(json.dumps(numerics_in_use()))\n"
    )
    names = (*NUMPY_VARIABLES, *PINNED_KERNELS)
    environment = {k: v for k, v in os.environ.items() if k not in names}
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, env=environment
    )
    used = json.loads(out.stdout)
    if not numerics.can_pin():
        assert not used["pinned"] and not used["variables"]
        return
    assert used["pinned"]
    assert "X86_V3" in used["numpy_simd"] and "X86_V4" not in used["numpy_simd"]
    assert not any(name.startswith("AVX512") for name in used["numpy_simd"])
    assert used["openblas_cores"] == ["Haswell"]
