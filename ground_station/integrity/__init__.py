"""Integrity: each fix tested, excluded, restored. Imports: config, maths, state, estimation."""
