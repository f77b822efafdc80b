"""Reading vehicles described for Gazebo: uuv_simulator's Fossen plugin blocks and gz-sim's
``Hydrodynamics`` system, with their thruster plugins, into a uvms-pin URDF and a thruster
table (`uvms_pin.model.importer.convert.import_model`)."""
