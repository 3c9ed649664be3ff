"""The viewer's environment (Rerun's analytics off in a configuration of the project's own) and
the live view's failures staying its own."""

from __future__ import annotations

import json

from mission.viewer.process import rerun_executable, viewer_environment


def test_the_viewer_runs_with_analytics_off_and_leaves_the_users_rerun_config_alone(
    tmp_path, monkeypatch
):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "user-config"))
    env = viewer_environment()
    config = tmp_path / "cache" / "bridge-uav-formation" / "rerun" / "config" / "rerun"
    assert env["XDG_CONFIG_HOME"] == str(config.parent)
    settings = json.loads((config / "analytics.json").read_text())
    assert settings["analytics_enabled"] is False and settings["analytics_id"]
    assert not (tmp_path / "user-config").exists()
    assert viewer_environment()["XDG_CONFIG_HOME"] == env["XDG_CONFIG_HOME"]  # idempotent
    assert rerun_executable().is_file()


def test_a_failing_live_view_says_so_once_and_never_stops_the_run(
    tmp_path, monkeypatch, capsys, along
):
    from mission.viewer import live

    calls = []

    def broken_feed(*_):
        calls.append(1)
        raise OSError("disk gone")

    monkeypatch.setattr(live, "RunFeed", broken_feed)
    monkeypatch.setattr(live.os, "nice", lambda _: 0)
    view = live.LiveView(tmp_path, along, None)
    view.poll(final=True)
    view.poll(final=True)
    view.finish()
    view.close()
    assert len(calls) == 1
    assert capsys.readouterr().err.strip() == "live view stopped: disk gone"
