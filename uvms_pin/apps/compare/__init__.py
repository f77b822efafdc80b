"""``uvms-pin compare-controllers``: one task, several controllers, one table (issue 14.2)."""
