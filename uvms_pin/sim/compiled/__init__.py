"""The compiled counterparts of the closed loop's parts, built from the Python objects."""
