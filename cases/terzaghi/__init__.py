"""Terzaghi's consolidation: its study measure and the window schemes' stability map."""
