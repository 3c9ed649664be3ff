"""Studies: sweeps of scenarios, points, methods, seeds. Imports: config, link, procs, analysis."""
