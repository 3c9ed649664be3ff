"""The vehicle process: CLI, sockets, pacing. Imports: config, world, link, procs, vehicle_sim."""
