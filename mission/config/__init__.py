"""Scenario settings: validated dataclasses, the YAML loader, input errors. Imports: nothing."""
