"""Mandel's problem: its study measure."""
