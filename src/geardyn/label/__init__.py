"""Motion labelling."""
