"""Mounting an arm URDF on a vehicle URDF, and splitting a UVMS back into both."""
