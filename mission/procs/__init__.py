"""Process helpers: forks, names, one-line CLI errors, atomic writes. Imports: config."""
