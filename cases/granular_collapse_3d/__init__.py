"""The axisymmetric granular column collapse: its run-out measure and the run at two resolutions."""
