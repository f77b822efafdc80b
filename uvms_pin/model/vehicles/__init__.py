"""Vehicles shipped with uvms-pin beyond their URDF: thruster layouts and thrust models."""
