"""World model: structure, rays, sky, GNSS, camera, frames, grid, zones. Imports: config."""
