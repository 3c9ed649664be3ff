"""What ``mission view`` checks of a finished run's files before it shows them: a file that is
not what it claims is refused on one line (exit status 2); one cut short is shown up to the
cut, with a warning saying where. The live view reads the same files as they grow and skips
what is not whole yet; a finished run has no such excuse."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mission.analysis.metrics import scan_records
from mission.analysis.records_file import RunShape, read_records_file
from mission.config.errors import InputError
from mission.viewer.tail import SNAPSHOT_NAME, VIEWED_IDS


def check_run_files(
    run_dir: Path, map_shape: tuple[int, ...], recorded: dict, shape: RunShape | None = None
) -> list[str]:
    """Raise InputError for a file of ``run_dir`` that is not a run's (its records of a run
    of ``shape``, if given); return warnings for files cut short (``recorded``: the run's
    summary.json, or {})."""
    warnings = _check_tlog(run_dir / "gcs.tlog")
    cycles, cut = _check_records(run_dir / "records.jsonl", shape)
    if cut:
        warnings.append(f"{run_dir / 'records.jsonl'}: its last line is cut: the view ends before")
    expected = recorded.get("control_cycles")
    if isinstance(expected, int) and cycles < expected:
        warnings.append(
            f"{run_dir / 'records.jsonl'}: {cycles} cycles where summary.json records "
            f"{expected}: cut short? the view shows the {cycles}"
        )
    _check_snapshots(run_dir / "g", map_shape)
    return warnings


def _check_tlog(path: Path) -> list[str]:
    data = path.read_bytes()
    records, end, clean = scan_records(data, VIEWED_IDS)
    if not records:
        raise InputError(str(path), "", "holds no vehicle message (not a run's tlog?)")
    if not clean:
        return [f"{path}: not MAVLink after byte {end:,} of {len(data):,}: the view ends there"]
    if end < len(data):
        return [f"{path}: cut in a record at byte {end:,} of {len(data):,}: the view ends there"]
    return []


def _check_records(path: Path, shape: RunShape | None) -> tuple[int, bool]:
    """(whole cycle records, whether the last line is cut)."""
    if (path.exists() or path.is_symlink()) and not path.is_file():
        raise InputError(str(path), "", "is not a regular file")
    found = read_records_file(path, shape)
    if not found.records:
        raise InputError(str(path), "", "holds no control cycle's record")
    return len(found.records), found.cut


def _check_snapshots(g_dir: Path, shape: tuple[int, ...]) -> None:
    if not g_dir.is_dir():
        return
    for path in sorted(g_dir.iterdir()):
        if not SNAPSHOT_NAME.match(path.name):
            continue
        try:
            values = np.load(path, allow_pickle=False)
        except (OSError, ValueError, EOFError):
            raise InputError(str(path), "", "not a G snapshot (no .npy array of numbers)") from None
        if values.size != int(np.prod(shape)) or not np.issubdtype(values.dtype, np.floating):
            problem = f"{values.dtype} x {values.size:,} values; the map is {shape}"
            raise InputError(str(path), "", f"not a G snapshot of this map ({problem})")
        if not np.isfinite(values).all() or (values < 0).any():
            raise InputError(str(path), "", "not a G snapshot (values not finite and >= 0)")
