"""The `uvms-pin` command."""
