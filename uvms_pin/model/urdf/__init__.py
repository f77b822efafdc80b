"""Reading a UVMS from a URDF file with the hydrodynamic extension (`load.load_uvms`)."""
