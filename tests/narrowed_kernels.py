"""``python -m tests.narrowed_kernels``: the environment that narrows this machine's numerical
kernels below what it has, as ``NAME=VALUE`` words for ``env``: numpy's every dispatched SIMD
group that the CPU supports disabled (its baseline kernels remain), and OpenBLAS's core set to
Sandybridge where the CPU has AVX (it has no AVX2 kernels). CI runs the determinism tests
again in it (.ci/run)."""

from __future__ import annotations

import numpy as np

from mission.procs.numerics import cpu_flags


def narrowed() -> list[str]:
    """The ``NAME=VALUE`` words."""
    umath = np._core._multiarray_umath
    found = [name for name in umath.__cpu_dispatch__ if umath.__cpu_features__.get(name)]
    words = [f"NPY_DISABLE_CPU_FEATURES={','.join(found)}"] if found else []
    if "avx" in cpu_flags():
        words.append("OPENBLAS_CORETYPE=Sandybridge")
    return words


if __name__ == "__main__":
    print(" ".join(narrowed()))
