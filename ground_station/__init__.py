"""The ground station (sees no zones nor truth). Imports: config, world, link, procs, codegen."""
