"""Each process's numerical set-up, made before numpy loads: one BLAS thread, and the same
numerical kernels on every x86-64 machine.

**One BLAS thread.** Every simulated vehicle, the ground station and its MPC helper are
separate processes doing 3x3 to 15x15 linear algebra, too small for BLAS to split. A
multi-threaded BLAS (numpy's OpenBLAS starts one worker per core) then only competes with the
other processes for the cores: its start-up alone costs each process ~60 ms of CPU, and a
mission's wall time was ~5 % longer with it.

**Pinned kernels.** numpy picks its SIMD kernels (X86_V3 is AVX2, X86_V4 and AVX512_* are
AVX-512) and OpenBLAS its core type by the CPU it finds. Their results differ in the last bits
(a sum or a product reduced in another order), and a closed loop with discrete choices (the
consistent set, a solver's branch, a margin) can carry a last-bit difference into different
decisions: Along AC seed 9 took 584 control cycles with AVX2 kernels and 547 with numpy's
AVX-512 ones (docs/reproduction.md). On an x86-64 machine with AVX2 and FMA (every Intel CPU
since 2013 and AMD since 2015), numpy is limited to its X86_V3 kernels and OpenBLAS (and MKL)
to their Haswell/AVX2 paths, so every such machine computes the same bits. Elsewhere (an older
x86, ARM) nothing is pinned and :func:`numerics_in_use` says so.

A value the user has set is kept, for each variable.
"""

from __future__ import annotations

import os
import platform
import sys
from pathlib import Path
from typing import Any

THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
NUMPY_FEATURES = "X86_V3"  # numpy >= 2.4's group: AVX AVX2 FMA3 F16C BMI BMI2 LZCNT MOVBE
PINNED_KERNELS = {
    "OPENBLAS_CORETYPE": "Haswell",  # numpy's and scipy's OpenBLAS
    "MKL_CBWR": "AVX2",  # MKL's conditional numerical reproducibility, where numpy uses MKL
}
NUMPY_VARIABLES = ("NPY_ENABLE_CPU_FEATURES", "NPY_DISABLE_CPU_FEATURES")
# /proc/cpuinfo's names of what X86_V3 and Haswell's kernels need
X86_V3_FLAGS = frozenset({"avx", "avx2", "fma", "f16c", "bmi1", "bmi2", "abm", "movbe"})


def prepare_numerics(cpuinfo: str = "/proc/cpuinfo") -> None:
    """One BLAS thread and the pinned kernels, each unless the environment already says
    (call this before anything imports numpy)."""
    for name in THREAD_VARIABLES:
        os.environ.setdefault(name, "1")
    if not can_pin(cpuinfo):
        return
    if not any(os.environ.get(name) for name in NUMPY_VARIABLES):
        os.environ["NPY_ENABLE_CPU_FEATURES"] = NUMPY_FEATURES
    for name, value in PINNED_KERNELS.items():
        os.environ.setdefault(name, value)


def can_pin(cpuinfo: str = "/proc/cpuinfo") -> bool:
    """Whether this machine runs the pinned kernels: Linux on x86-64 with AVX2 and FMA."""
    if sys.platform != "linux" or platform.machine().lower() not in ("x86_64", "amd64"):
        return False
    return X86_V3_FLAGS.issubset(cpu_flags(cpuinfo))


def cpu_flags(cpuinfo: str = "/proc/cpuinfo") -> frozenset[str]:
    """The first CPU's feature flags as Linux lists them (empty where it does not)."""
    try:
        with open(cpuinfo, encoding="utf-8", errors="replace") as lines:
            for line in lines:
                if line.startswith("flags"):
                    return frozenset(line.partition(":")[2].split())
    except OSError:
        pass
    return frozenset()


def cpu_model(cpuinfo: str = "/proc/cpuinfo") -> str:
    """The CPU's model name (``platform.processor()`` where Linux does not say)."""
    try:
        with open(cpuinfo, encoding="utf-8", errors="replace") as lines:
            for line in lines:
                if line.startswith("model name"):
                    return line.partition(":")[2].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def numerics_in_use() -> dict[str, Any]:
    """What this process computes with: numpy's SIMD kernels (the baseline and the dispatched
    groups it uses), the kernel variables in effect, and whether they are the pinned ones."""
    import numpy as np

    umath = np._core._multiarray_umath
    found = [name for name in umath.__cpu_dispatch__ if umath.__cpu_features__.get(name)]
    variables = {
        name: os.environ.get(name)
        for name in (*NUMPY_VARIABLES, *PINNED_KERNELS)
        if os.environ.get(name)
    }
    pinned = variables.get("NPY_ENABLE_CPU_FEATURES") == NUMPY_FEATURES and all(
        variables.get(name) == value for name, value in PINNED_KERNELS.items()
    )
    return {
        "numpy_simd": [*umath.__cpu_baseline__, *found],
        "openblas_cores": openblas_cores(),
        "variables": variables,
        "pinned": pinned,
    }


_CORENAME_FUNCTIONS = (
    "openblas_get_corename",
    "scipy_openblas_get_corename64_",
    "scipy_openblas_get_corename",
)


def openblas_cores() -> list[str]:
    """The core type each OpenBLAS loaded in this process runs (numpy's, and scipy's once
    scipy's linear algebra is loaded), as OpenBLAS names it; empty where none is loaded."""
    import ctypes

    try:
        maps = Path("/proc/self/maps").read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError:
        return []
    libraries = sorted({line.split()[-1] for line in maps if "openblas" in line.split()[-1]})
    cores = []
    for library in libraries:
        loaded = ctypes.CDLL(library)
        for name in _CORENAME_FUNCTIONS:
            function = getattr(loaded, name, None)
            if function is not None:
                function.restype = ctypes.c_char_p
                cores.append(function().decode())
                break
    return cores
