"""Speed and accuracy figures (``aerostat-gym bench``): the compiled core (``core``), the wind
sampler (``wind``), the linear sweep (``linear``), the environments (``env``) and the peer
comparison with MoorDyn (``moordyn``, needs the ``bench`` extra)."""

from .core import format_text, run_bench

__all__ = ["format_text", "run_bench"]
