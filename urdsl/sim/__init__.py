"""Virtual UR controller serving the controller's protocols on loopback."""
