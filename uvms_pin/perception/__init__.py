"""The sensors that see the world: cameras and sonars over one ray caster, on the CPU.

`uvms_pin.perception.scene` is the world as they see it (`caster`, `shapes`, `mesh`);
`camera` and `sonar` are the kinds of sensor (`sensor`: what a kind is, and their registry);
`suite` fires a run's sensors over its logged states. The physics never imports this layer.
"""
