"""Process helpers: forks, names, CLI errors, atomic writes, the real-time beat, casadi's
compile cache. Imports: config."""
