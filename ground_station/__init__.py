"""The ground-station process (never sees zones or truth). Imports: config, world, link, procs."""
