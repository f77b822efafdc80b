"""The world a UVMS works in: fixed objects (the seafloor, boxes, rocks, pipes) that every
body's collision geometry touches with compliant contact and Coulomb friction."""
