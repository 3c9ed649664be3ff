"""`mission run` shows what the ground station says of a first run's compilation."""

from __future__ import annotations

from ground_station.support_mpc import nlp_cache
from mission.runs.orchestrator import COMPILE_NEWS, LogRelay


def test_the_news_are_the_ground_stations_own_words():
    assert COMPILE_NEWS == (nlp_cache.COMPILING, nlp_cache.COMPILED)


def test_each_news_line_is_shown_once_and_only_when_whole(tmp_path, capsys):
    log = tmp_path / "ground_station.log"
    log.write_text("ground station listening on 127.0.0.1:5\n")
    relay = LogRelay(log, COMPILE_NEWS)
    relay.poll()
    assert capsys.readouterr().err == ""
    with log.open("a") as handle:
        handle.write(f"ground station: {COMPILE_NEWS[0]} with gcc: once per machine\n")
        handle.write(f"ground station: {COMPILE_NEWS[0]} with gcc: once per machine\n")  # helper
        handle.write(f"ground station: {COMPILE_NEWS[1]} in 9")  # not a whole line yet
    relay.poll()
    assert capsys.readouterr().err == f"{COMPILE_NEWS[0]} with gcc: once per machine\n"
    with log.open("a") as handle:
        handle.write(".5 s\n")
    relay.poll()
    relay.poll()
    assert capsys.readouterr().err == f"{COMPILE_NEWS[1]} in 9.5 s\n"


def test_a_missing_log_is_no_news(tmp_path, capsys):
    LogRelay(tmp_path / "none.log", COMPILE_NEWS).poll()
    assert capsys.readouterr().err == ""


def test_a_first_runs_compile_time_is_read_from_the_ground_stations_log(tmp_path):
    from mission.runs.orchestrator import _compile_time

    log = tmp_path / "ground_station.log"
    log.write_text(
        "ground station listening on 127.0.0.1:5000\n"
        "ground station: compiling the support MPC with gcc: once per machine, cached\n"
        "ground station: compiled the support MPC in 26.3 s\n"
    )
    assert _compile_time(log) == 26.3  # left out of the run's real-time factor
    log.write_text("ground station listening on 127.0.0.1:5000\n")
    assert _compile_time(log) == 0.0 and _compile_time(tmp_path / "none.log") == 0.0
