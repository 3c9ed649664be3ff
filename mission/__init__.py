"""Everything around the two processes, in role packages, and the CLI. Imports: all."""
