"""Kinematics of the UR family: models, forward/inverse kinematics and URScript pose math."""
