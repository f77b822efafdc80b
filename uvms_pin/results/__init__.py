"""Results: a run's Rollout (arrays and typed status), its tables, metrics and figures,
output directories and files written whole. The bottom layer: it imports nothing of
uvms-pin but `uvms_pin.errors`."""
