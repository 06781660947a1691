"""Signals: the accelerometer chain a sensor on the plate measures through (sensor),
measurement noise (noise) and the sensor figures.
"""
