"""One simulated vehicle process. Imports: config, world, link, procs, codegen."""
