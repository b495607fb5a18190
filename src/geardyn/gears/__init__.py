"""Gear science that knows no paper: involute geometry of internal and external pairs (contact
ratio, interference, tip thickness, cutter limits), ISO 6336-1 mesh stiffness and the parabolic
time-varying stiffness, and the backlash (dead-zone) function."""
