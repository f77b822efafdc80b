"""The controllers the PPC is compared with: PI force, impedance, computed torque."""
