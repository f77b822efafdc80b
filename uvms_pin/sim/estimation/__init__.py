"""Estimation of the vehicle's navigation state from its navigation sensors: an error-state
Kalman filter (`eskf`), its configuration (`spec`) and the estimator in the loop
(`estimator`)."""
