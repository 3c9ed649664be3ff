"""Numerical code compiled to C once per machine and cached (casadi). Imports: nothing."""
