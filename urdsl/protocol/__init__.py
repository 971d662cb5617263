"""Sans-I/O codecs for the controller's interfaces (realtime, primary, RTDE, dashboard)."""
