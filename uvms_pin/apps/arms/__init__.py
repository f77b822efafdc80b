"""Arms to mount on a vehicle and the ``compare-arms`` study (issue 5)."""
