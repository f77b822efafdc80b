"""Constraints solved implicitly: joint limits and contacts as velocity-level
complementarity problems over one control period, solved by Pinocchio's ADMM constraint
solver (docs/physics.md, "Constraints solved implicitly")."""
