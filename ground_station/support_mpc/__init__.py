"""The support MPC: its NLP, solvers and margins. Imports: config, world, procs, estimation."""
