"""Who is in the formation, who inspects. Imports: config, world, state, estimation, support_mpc."""
