"""A PolyScope project: the files that make up one program (host programs, included script
files, subprograms, installation variables) and the names each file can see."""
