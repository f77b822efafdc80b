"""Hydrodynamics as small pure functions returning body-frame wrenches."""
