"""Who does what in the formation (issue 33): the work UAV's own GNSS where it is trustworthy.
Imports: config, world, ground_station."""
