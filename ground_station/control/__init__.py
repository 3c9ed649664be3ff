"""The control cycle. Imports: config, world, state, estimation, integrity, support_mpc, roles."""
