"""The native half of :mod:`counterpoise` (JSON text in, JSON text out)."""

from typing import Optional

__version__: str

class CounterpoiseError(ValueError):
    """A case, an option or a study that counterpoise refuses; the message names the field."""

def validate(text: str, path: str) -> str: ...
def variants(text: str, path: str, dmax: Optional[int] = None) -> str: ...
def run_study(
    text: str,
    path: str,
    dmax: Optional[int] = None,
    minimax: bool = False,
    resolution: Optional[float] = None,
    tolerance: Optional[float] = None,
    gap: Optional[float] = None,
    max_nodes: Optional[int] = None,
    seed: Optional[int] = None,
) -> str: ...
def import_urdf(
    urdf: str, name: str, base: Optional[str] = None, tip: Optional[str] = None
) -> str: ...
