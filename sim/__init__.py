"""The simulated world: PyBullet scenes from world files, robot models, timed motion, sensors.

Imports nothing else of ours: it is the world, not the robot's mind.
"""
