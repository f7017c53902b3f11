"""The deployed structure: its supports, and its panels and hinges under load (OpenSees)."""
