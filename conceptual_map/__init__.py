"""The robot's spatial knowledge: metric maps, place map, conceptual layer (chain graph), QSR.

Never imports `sim`: everything it knows comes from sensor data handed over by the executor.
"""
