"""Figure functions: each takes datasets and returns a matplotlib Figure (no file I/O)."""
