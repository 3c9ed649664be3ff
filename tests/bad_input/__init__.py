"""The bad-input table: its cases (files, then commands) and what builds them."""
