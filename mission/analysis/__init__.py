"""Analysis of runs and worlds: tlog metrics, figures. Imports: config, world, link, procs."""
