"""PolyScope files: programs (``.urp``), installations (``.installation``) and installation
variables (``.variables``)."""
