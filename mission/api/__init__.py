"""The Python API: run, load_run, study. Imports: all but mission.commands, mission.bench."""
