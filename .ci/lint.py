"""Fail on any `snakemake --lint` finding except the note asking for a conda environment or container
per rule (this project installs with pip). Reads the lint text from standard input."""

import re
import sys

text = sys.stdin.read()
titles = re.findall(r"^\s+\* (.+?):?$", text, re.M)
others = [t for t in titles if not t.startswith("Specify a conda environment or container")]
print(f"snakemake --lint: {len(titles)} notes, {len(others)} other than the conda/container note")
for title in sorted(set(others)):
    print(f"  {title}")
sys.exit(1 if others or not titles else 0)
