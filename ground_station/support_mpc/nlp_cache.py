"""The support MPC's NLPs compiled to shared libraries with the system C compiler, and cached
(:mod:`mission.codegen.casadi_cache`): a plan takes about a fifth of the time it takes with
casadi's interpreter. The first run generates and compiles (every NLP at once, one compiler
process each); later runs load the cached libraries and build nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager

import casadi as ca

from mission.codegen import casadi_cache
from mission.codegen.casadi_cache import Build, FunctionBuild, KeyedBuild, NlpBuild, c_compiler
from mission.codegen.news import Compiling

__all__ = ["FunctionBuild", "KeyedBuild", "NlpBuild", "c_compiler"]

SUPPORT_MPC = Compiling("ground station", "the support MPC", "support_mpc")


@contextmanager
def compiled_libraries(builds: list[Build]) -> Iterator[list[str | None]]:
    """The libraries, in a private scratch folder where the cache cannot take them."""
    with casadi_cache.compiled_libraries(builds, SUPPORT_MPC) as libraries:
        yield libraries


def compiled_keyed_function(
    name: str, key: str, make: Callable[[], ca.Function], compiled: bool = True
) -> ca.Function:
    """``make()``'s function compiled and cached under ``key``: a cache hit loads it without
    calling ``make()`` (interpreted, ``make()``, without a compiler)."""
    return casadi_cache.compiled_keyed_function(name, key, make, SUPPORT_MPC, compiled)
