"""World model: structure, rays, sky, GNSS, camera, frames, grid, zones, wind. Imports: config."""
