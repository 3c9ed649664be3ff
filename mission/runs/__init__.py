"""The orchestrator of `mission run`. Imports: all but mission.commands, mission.bench."""
