"""Analysis of runs and worlds: metrics, figures. Imports: config, world, link, procs, maths."""
