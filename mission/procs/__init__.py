"""Process helpers: forks, names, CLI errors, atomic writes, beat. Imports: config."""
