"""Integrity: each fix tested, excluded, restored. Imports: config, maths, ground_station."""
