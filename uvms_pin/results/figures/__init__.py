"""Figures of a rollout (matplotlib, imported only here): the paper's force and funnel
figures and the pose, velocity and energy plots; `plot_rollout` picks them by name."""
