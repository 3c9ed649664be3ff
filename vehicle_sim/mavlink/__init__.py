"""The vehicle's MAVLink side: messages, protocols, commands. Imports: config, world, link."""
