"""The paper's outburst: its report, headline numbers, sensitivity study and ensembles."""
