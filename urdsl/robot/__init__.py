"""Talking to a robot over sockets: sender, state reader, RTDE recorder, dashboard."""
