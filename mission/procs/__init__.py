"""Process helpers: forks, names, CLI errors, atomic writes, beat, casadi cache. Imports: config."""
