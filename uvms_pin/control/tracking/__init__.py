"""Tracking tasks: reference paths (`trajectory`), what is tracked and in which frame
(`task`), the task-priority kinematic level (`task_priority`) and the dynamic levels that
follow its velocity references (`dynamic_level`), and resolved-acceleration computed torque
on the same tasks (`resolved_acceleration`)."""
