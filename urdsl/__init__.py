"""urdsl: write, check, send and observe Universal Robots programs.

The one-call API for the language core::

    import urdsl
    tree = urdsl.parse(text, filename="prog.script")
    text = urdsl.format(tree)
"""

from __future__ import annotations

__version__ = "0.1.0"
