"""Mathematics every role may use (distributions, tests). Imports: nothing."""
