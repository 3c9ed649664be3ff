"""Support-path planner and zone placement. Imports: config, world, link, procs, analysis."""
