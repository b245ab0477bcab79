"""Gas drainage through a face: its similarity solution, study measure and figures."""
