"""Adapters that show results: matplotlib figures, meshcat scenes. The core never imports these."""
