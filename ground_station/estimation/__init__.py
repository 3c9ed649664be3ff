"""What the station believes: fused estimates, the map G. Imports: config, world, state."""
