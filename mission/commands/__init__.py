"""The main command line's commands, one module each (its parser and its run). Imports: all."""
