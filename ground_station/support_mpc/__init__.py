"""The support MPC: NLP, solvers, margins. Imports: config, world, procs, codegen, estimation."""
