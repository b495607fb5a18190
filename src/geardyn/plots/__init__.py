"""Figure builders (matplotlib, Agg-safe; no plt.show, no file I/O)."""
