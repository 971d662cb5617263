"""Package data: the URScript grammar (``urscript.lark``), loaded by :mod:`urdsl.script.parser`."""
