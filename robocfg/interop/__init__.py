"""Reading and writing other tools' robot configs (config level only: no simulator)."""
