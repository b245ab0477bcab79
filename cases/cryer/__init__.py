"""Cryer's sphere: its measure and its resolution study."""
