"""Speed and accuracy figures (``aerostat-gym bench``): the compiled core (``core``), the wind
sampler (``wind``), the linear sweep (``linear``), the environments (``env``), the peer
comparisons with MoorDyn (``moordyn``, the static line; ``moordyn_dynamic``, the top end
driven; both need the ``bench`` extra) and the environment's soak (``soak``)."""

from .core import format_text, run_bench

__all__ = ["format_text", "run_bench"]
