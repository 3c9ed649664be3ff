"""World model: structure, sky, GNSS, camera, frames, grid, routes, zones, wind. Imports: config."""
