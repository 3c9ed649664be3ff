"""The station's links and clock: UDP, tlog, time sync. Imports: config, world, link, procs."""
