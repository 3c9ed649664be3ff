"""The MAVLink layer of both sides, waypoint and plan files. Imports: config, world, procs."""
