"""``mission view RUN --web`` in a real browser: headless Chromium loads the served web viewer,
and its screenshot's 3-D view shows the bridge and the UAVs in their colours. Also: the
servers listen on loopback only, and Ctrl-C leaves no viewer process behind."""

from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from mission.viewer import frame as f
from tests.browser import Browser, chromium
from tests.processes import ROOT

pytestmark = pytest.mark.slow  # runs a mission, a viewer and a browser
TOLERANCE = 45  # per channel: shading moves the bridge's colour this far
HUE_TOLERANCE_DEG = 10  # a shaded sphere keeps its hue, not its brightness
LOAD_TIMEOUT_S = 120.0


def _require_chromium() -> None:
    if chromium() is None:
        if os.environ.get("REQUIRE_BROWSER"):  # set by .ci/run, which installs chromium
            pytest.fail("no chromium executable")
        pytest.skip("no chromium executable (Debian: apt install chromium)")


def _pixels_near(image: np.ndarray, colour: tuple[int, int, int]) -> int:
    return int(np.all(np.abs(image - np.array(colour)) <= TOLERANCE, axis=2).sum())


def _pixels_of_hue(image: np.ndarray, colour: tuple[int, int, int]) -> int:
    """Pixels of the colour's hue, saturated and bright enough to be the colour shaded."""
    from matplotlib.colors import rgb_to_hsv

    hsv, (hue, _, _) = rgb_to_hsv(image / 255.0), rgb_to_hsv(np.array(colour) / 255.0)
    distance = np.abs((hsv[..., 0] - hue + 0.5) % 1.0 - 0.5) * 360
    vivid = (hsv[..., 1] >= 0.45) & (hsv[..., 2] >= 0.35)
    return int(((distance <= HUE_TOLERANCE_DEG) & vivid).sum())


def _panels(png: bytes) -> tuple[np.ndarray, np.ndarray]:
    """The screenshot's 3-D view and top view (the layout's left column), RGB."""
    from PIL import Image

    image = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)
    height, width = image.shape[:2]
    left = image[:, : int(0.58 * width)]
    formation = left[int(0.07 * height) : int(0.55 * height)]
    return formation, left[int(0.62 * height) : int(0.95 * height)]


def _seen(png: bytes) -> dict[str, int]:
    """How many pixels show the bridge (in the 3-D view) and each UAV's track (top view)."""
    formation, top = _panels(png)
    found = {"bridge": _pixels_near(formation, f.BRIDGE_COLOUR)}
    for name in ("work", "support-1", "support-2", "support-3"):
        found[name] = _pixels_of_hue(top, f.colour_of(name))
    return found


def _shows_everything(found: dict[str, int]) -> bool:
    return found["bridge"] > 5000 and all(n >= 30 for n in found.values())


def _start_view(run) -> tuple[subprocess.Popen, str]:
    view = subprocess.Popen(
        [sys.executable, "-m", "mission", "view", str(run), "--web"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    line = view.stdout.readline()
    assert line.startswith("viewer at http://127.0.0.1:"), line + view.stderr.read()
    return view, line.split()[2]


def _listening_ports(pid: int) -> list[str]:
    """The local addresses the process listens on (TCP), from ``ss``."""
    out = subprocess.run(["ss", "-ltnpH"], capture_output=True, text=True).stdout
    return [row.split()[3] for row in out.splitlines() if f"pid={pid}," in row]


def test_the_web_viewer_shows_the_bridge_and_the_uavs(short_run, tmp_path):
    _require_chromium()
    run, _ = short_run
    view, url = _start_view(run)
    viewers = subprocess.run(["pgrep", "-P", str(view.pid)], capture_output=True, text=True)
    viewer_pids = [int(p) for p in viewers.stdout.split()]
    browser = None
    try:
        assert viewer_pids
        addresses = [a for pid in viewer_pids for a in _listening_ports(pid)]
        assert len(addresses) == 2 and all(a.startswith("127.0.0.1:") for a in addresses)
        browser = Browser(url + "&renderer=webgl")  # WebGL: swiftshader has no WebGPU
        deadline = time.monotonic() + LOAD_TIMEOUT_S
        while True:
            png = browser.screenshot()
            found = _seen(png)
            if _shows_everything(found) or time.monotonic() > deadline:
                break
            time.sleep(2)
        (tmp_path / "view.png").write_bytes(png)
        assert _shows_everything(found), f"not all in view: {found} (see {tmp_path})"
    finally:
        if browser is not None:
            browser.close()
        view.send_signal(signal.SIGINT)
        assert view.wait(timeout=30) == 0
    time.sleep(0.5)
    assert not [p for p in viewer_pids if os.path.exists(f"/proc/{p}")], "a viewer outlived it"
