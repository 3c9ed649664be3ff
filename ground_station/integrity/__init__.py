"""Integrity: each support's fix tested, excluded, restored. Imports: config, ground_station."""
