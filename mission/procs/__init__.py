"""Process helpers: forks, names, CLI errors, atomic writes, the real-time beat. Imports: config."""
