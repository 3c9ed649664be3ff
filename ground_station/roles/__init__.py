"""Who does what in the formation (issue 33). Imports: config, world, ground_station."""
