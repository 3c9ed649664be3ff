"""Mission layer: scenarios, world model (structure, sky, GNSS, camera), planning and runs."""
