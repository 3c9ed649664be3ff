"""Optional packages the test extra installs (Ray, Embree): a test that needs one skips where
it is missing, except in CI (``REQUIRE_EXTRAS`` set by ``.ci/run``), where a missing one is a
failure: a skip there would hide that the install went wrong."""

from __future__ import annotations

import importlib
import os
from types import ModuleType

import pytest


def required(module: str) -> ModuleType:
    """The module, or a skip (a failure under ``REQUIRE_EXTRAS``)."""
    try:
        return importlib.import_module(module)
    except ImportError as error:
        if os.environ.get("REQUIRE_EXTRAS"):
            pytest.fail(f"{module} is in the test extra but does not import: {error}")
        pytest.skip(f"{module} is not installed")


def embree_available() -> bool:
    """Whether embreex works here (it has wheels for x86-64 only); required under
    ``REQUIRE_EXTRAS`` on x86-64."""
    import platform

    from mission.world.rays import rtcore_scene

    x86 = platform.machine().lower() in ("x86_64", "amd64")
    if rtcore_scene is None and x86 and os.environ.get("REQUIRE_EXTRAS"):
        pytest.fail("embreex is in the dependencies for x86-64 but does not import")
    return rtcore_scene is not None


def require_c_compiler() -> str:
    """The system C compiler the casadi cache uses, or a skip (a failure under
    ``REQUIRE_EXTRAS``: CI's machine has one, and without it nothing is compiled)."""
    from mission.codegen.casadi_cache import c_compiler

    compiler = c_compiler()
    if compiler is None:
        if os.environ.get("REQUIRE_EXTRAS"):
            pytest.fail("no C compiler (gcc or cc) on the path: the casadi cache compiles nothing")
        pytest.skip("no C compiler: casadi's code is interpreted here")
    return compiler
