"""A run in 3-D (Rerun): replay, live, recordings. Imports: config, world, link, procs, analysis."""
