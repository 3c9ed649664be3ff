"""The process: CLI, sockets, pacing. Imports: config, world, link, procs, dynamics, vehicle_sim."""
