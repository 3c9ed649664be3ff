"""Who flies in the formation, who inspects. Imports: config, world, ground_station, support_mpc."""
