"""The bar stopped at one end: its study measure."""
