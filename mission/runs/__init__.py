"""Whole runs: orchestrator, batches, benchmarks, detached run. Imports: all but mission.cli."""
