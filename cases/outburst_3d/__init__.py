"""The paper's outburst at a heading in 3D: its report and headline numbers beside the plane case's."""
