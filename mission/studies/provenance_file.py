"""A study's ``provenance.json`` beside its ``results.csv``, and the footer (and, for a
historical study, the first line) of its ``report.md``.

provenance.json holds the git commit the study was made with and whether the tree was dirty,
the package's version, the code version its run keys carry (the digest of the files a run
executes), the versions of casadi, numpy, scipy, pymavlink and Python, the machine and its
numerical kernels, and the canary (:mod:`mission.studies.canary`). A study whose numbers today's
code no longer gives, kept as it was, says ``"historical": "<why>"``; its report says so first.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from mission.config.errors import InputError
from mission.procs.atomic import write_text_atomically
from mission.procs.json_files import read_json_object
from mission.procs.provenance import code_identity, environment, last_commit_of

PROVENANCE_FILE = "provenance.json"


def made_now(name: str, code: str) -> dict[str, Any]:
    """What a study made now with the code whose version is ``code`` says of its making: the
    commit, the packages, the machine (read once a study: git and the numerics cost tens of
    milliseconds)."""
    return {"study": name, **code_identity(), "code_version": code, **environment()}


def study_provenance(
    made: dict[str, Any], canary: dict[str, Any], run_numerics: dict[str, Any] | None
) -> dict[str, Any]:
    """The provenance of a study (``made``: :func:`made_now`); the machine's numerics are
    ``run_numerics`` where a run said what it computed with (its summary's), else this
    process's."""
    provenance = json.loads(json.dumps(made))  # a copy
    if run_numerics:
        provenance["machine"]["numerics"] = run_numerics
    return {**provenance, "canary": canary, "historical": None}


def write_provenance(out_dir: Path, provenance: dict[str, Any]) -> None:
    """provenance.json, written whole or not at all."""
    text = json.dumps(provenance, indent=2, sort_keys=False) + "\n"
    write_text_atomically(out_dir / PROVENANCE_FILE, text)


def read_provenance(out_dir: Path) -> dict[str, Any] | None:
    """A study folder's provenance.json (None where it has none); one that cannot be read as
    an object is bad input naming the file."""
    return read_json_object(out_dir / PROVENANCE_FILE)


def historical_line(provenance: dict[str, Any] | None) -> str | None:
    """The report's first line for a study marked historical (None otherwise)."""
    if not provenance or not provenance.get("historical"):
        return None
    made = "committed with" if provenance.get("committed_with") else "made with"
    return (
        f"> **Historical**: {made} commit {_short(provenance.get('commit'))}; today's code "
        f"does not give these numbers ({provenance['historical']})."
    )


def report_footer(provenance: dict[str, Any] | None) -> list[str]:
    """The report's closing section: where its numbers came from."""
    if not provenance:
        return []
    tree = {True: "with uncommitted changes", False: "a clean tree"}.get(
        provenance.get("dirty"), "the tree's state unknown"
    )
    made = (
        f"Made with commit {_short(provenance.get('commit'))} ({tree}) of bridge-uav-formation "
        f"{provenance.get('version')}, code version `{str(provenance.get('code_version'))[:12]}` "
        "(the digest of the files a run executes, which every run key carries)"
    )
    lines = ["", "## Provenance", "", made + _where(provenance) + "."]
    canary = provenance.get("canary") or {}
    if canary.get("runs"):
        told = "; ".join(f"{r['run']} `{r['decisions_digest']}`" for r in canary["runs"])
        lines += ["", f"Canary `{canary.get('digest')}`: {told}."]
    lines += [
        "",
        "provenance.json holds the same. `mission study FILE --verify N --against DIR` makes N "
        "of these rows again and compares every column but the timings.",
    ]
    return lines


def _where(provenance: dict[str, Any]) -> str:
    machine = provenance.get("machine")
    if not machine:
        return ""
    packages = provenance.get("packages") or {}
    versions = ", ".join(f"{name} {version}" for name, version in packages.items())
    numerics = machine.get("numerics") or {}
    kernels = (
        "pinned numerical kernels" if numerics.get("pinned") else "numerical kernels not pinned"
    )
    simd = " ".join(numerics.get("numpy_simd") or [])
    blas = ", ".join(numerics.get("openblas_cores") or []) or "none loaded"
    return (
        f", on {machine.get('system')} {machine.get('architecture')} ({machine.get('cpu')}) "
        f"with Python {provenance.get('python')}, {versions}; {kernels} "
        f"(numpy {simd}; OpenBLAS {blas})"
    )


def _short(commit: Any) -> str:
    return f"`{commit[:12]}`" if isinstance(commit, str) and commit else "unknown"


def mark_historical(out_dir: Path, why: str) -> None:
    """Mark a study historical (its numbers are not what today's code gives), saying why, in
    its provenance.json; one made before provenance existed gets one naming the last commit
    that changed its results.csv (the commit they were committed with)."""
    if not why.strip():
        raise InputError("command line", "--historical", "must say why the study is historical")
    provenance = read_provenance(out_dir) or {
        "study": out_dir.name,
        "commit": last_commit_of(out_dir / "results.csv"),
        "committed_with": True,  # the commit that committed the results, not one that ran them
    }
    provenance["historical"] = why.strip()
    write_provenance(out_dir, provenance)
