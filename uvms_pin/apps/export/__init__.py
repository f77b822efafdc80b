"""Export a UVMS to other simulators' formats (MJCF for MuJoCo)."""
