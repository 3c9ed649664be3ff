"""The vehicle's sensors, their failures, the scenario's faults. Imports: config, world, mavlink."""
