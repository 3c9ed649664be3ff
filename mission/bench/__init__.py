"""The benchmarks (`mission bench`), the detached run. Imports: all but mission.commands."""
