"""counterpoise: exact static balancing of mechanisms with counterweights and springs.

Load a case (a file or a dict), import a URDF robot, list every set of at most Dmax
counterweights and springs with its verdict, and run the whole study (balance search,
certified optimisation, ranking) — the same computation as the ``counterpoise`` command line,
returned as Python objects with NumPy arrays for the torque curves.

>>> import counterpoise
>>> case = counterpoise.load_case("cases/two_link.json")
>>> results = case.run_study()
>>> best = results.ranked[0]
>>> best.label, best.dqtr                                        # doctest: +SKIP
('m1 + m2', -100.0)

Errors raise :class:`CounterpoiseError` (a ``ValueError``) with the command line's message:
a refused case names each field, line and column.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Union

import numpy as np

from . import _counterpoise
from ._counterpoise import CounterpoiseError

__all__ = [
    "Case",
    "CounterpoiseError",
    "Results",
    "TorqueChart",
    "Variant",
    "VariantRecord",
    "import_urdf",
    "load_case",
]
__version__: str = _counterpoise.__version__

PathLike = Union[str, "os.PathLike[str]"]


@dataclass(frozen=True)
class Variant:
    """One set of balancing elements and the exact search's verdict on it.

    ``status`` is ``balanced``, ``degenerate``, ``unrealizable``, ``infeasible`` or
    ``undecided`` (never a verdict); ``document`` is the variant's entry of the
    ``variants --json`` document (relations, witness parameters, residuals).
    """

    elements: List[str]
    status: str
    variant_class: str
    reason: Optional[str]
    document: Dict[str, Any] = field(repr=False)

    @property
    def label(self) -> str:
        """The elements joined as the reports write them, e.g. ``m1 + K12``."""
        return " + ".join(self.elements)


@dataclass(frozen=True)
class VariantRecord:
    """One variant of a study's results (an entry of results.json's ``variants``).

    Feasible variants carry their verified physical parameters, the optimiser's account and
    the Phase 3 indicators (ΔQTR, ΔQIT, ΔR in percent) and rank.
    """

    id: int
    elements: List[str]
    status: str
    rank: Optional[int]
    dqtr: Optional[float]
    dqit: Optional[float]
    dr: Optional[float]
    verification_residual: Optional[float]
    document: Dict[str, Any] = field(repr=False)

    @property
    def label(self) -> str:
        return " + ".join(self.elements)

    @property
    def parameters(self) -> Optional[Dict[str, Any]]:
        """Masses, offsets, stiffnesses and anchors (SI units), for a feasible variant."""
        return self.document.get("parameters")


@dataclass(frozen=True)
class TorqueChart:
    """Motor torque of one actuator along one task for several mechanisms.

    ``t`` (s) and every curve (N·m) are NumPy arrays of the same length; ``curves`` maps each
    mechanism's label (``UB`` for the unbalanced robot first) to its torque.
    """

    actuator: str
    task: tuple
    critical_for: List[str]
    t: np.ndarray = field(repr=False)
    curves: Dict[str, np.ndarray] = field(repr=False)


class Results:
    """A finished study: results.json as a dict (``document``) and typed views of it."""

    def __init__(self, document: Dict[str, Any]):
        self.document = document
        self.variants: List[VariantRecord] = [
            VariantRecord(
                id=v["id"],
                elements=[e["label"] for e in v["elements"]],
                status=v["status"],
                rank=v.get("rank"),
                dqtr=v.get("dqtr"),
                dqit=v.get("dqit"),
                dr=v.get("dr"),
                verification_residual=v.get("verification_residual"),
                document=v,
            )
            for v in document["variants"]
        ]
        self.torque_charts: List[TorqueChart] = [
            TorqueChart(
                actuator=c["actuator"],
                task=tuple(c["task"]),
                critical_for=list(c["critical_for"]),
                t=np.asarray(c["t"], dtype=float),
                curves={k["label"]: np.asarray(k["values"], dtype=float) for k in c["curves"]},
            )
            for c in document.get("torque_charts", [])
        ]

    @property
    def ranked(self) -> List[VariantRecord]:
        """The feasible variants in rank order (rank 1 first)."""
        return sorted((v for v in self.variants if v.rank is not None), key=lambda v: v.rank)

    @property
    def recommendation(self) -> Optional[Dict[str, Any]]:
        """The report's decision section (the recommended variant and why), if any."""
        return self.document.get("decision")

    def to_json(self) -> str:
        """The results as results.json's text."""
        return json.dumps(self.document, indent=2)

    def __repr__(self) -> str:
        counts = ", ".join(
            f"{c['total']} {c['status']}" for c in self.document.get("counts", []) if c["total"]
        )
        return f"<Results of {self.document['metadata']['case_name']!r}: {counts}>"


class Case:
    """A validated case: the mechanism, its balancing section and its tasks.

    Build one with :func:`load_case` (a file or a dict) or :func:`import_urdf`.
    """

    def __init__(self, text: str, path: str = "<case>"):
        self._text = text
        self._path = path
        summary = json.loads(_counterpoise.validate(text, path))
        self.name: str = summary["name"]
        self.bodies: List[str] = summary["bodies"]
        self.coordinates: List[str] = summary["coordinates"]
        self.joints: List[str] = summary["joints"]
        self.actuators: List[str] = summary["actuators"]
        self.dmax: Optional[int] = summary["dmax"]

    @classmethod
    def from_file(cls, path: PathLike) -> "Case":
        """Loads a case file (JSON)."""
        path = os.fspath(path)
        return cls(_read(path), path)

    @classmethod
    def from_dict(cls, case: Mapping[str, Any]) -> "Case":
        """A case given as a dict (the case file's JSON structure)."""
        return cls(json.dumps(case, indent=1), "<case>")

    def to_dict(self) -> Dict[str, Any]:
        """The case as a dict (the case file's JSON structure)."""
        return json.loads(self._text)

    def variants(self, dmax: Optional[int] = None) -> List[Variant]:
        """Every set of at most ``dmax`` elements (default: the case's) with its verdict."""
        doc = json.loads(_counterpoise.variants(self._text, self._path, dmax))
        return [
            Variant(
                elements=[e["label"] for e in v["elements"]],
                status=v["status"],
                variant_class=v["class"],
                reason=v.get("reason"),
                document=v,
            )
            for v in doc["variants"]
        ]

    def run_study(
        self,
        dmax: Optional[int] = None,
        *,
        minimax: bool = False,
        resolution: Optional[float] = None,
        tolerance: Optional[float] = None,
        gap: Optional[float] = None,
        max_nodes: Optional[int] = None,
        seed: Optional[int] = None,
    ) -> Results:
        """The whole study, as ``counterpoise run`` computes it (see its options)."""
        text = _counterpoise.run_study(
            self._text, self._path, dmax, minimax, resolution, tolerance, gap, max_nodes, seed
        )
        return Results(json.loads(text))

    def __repr__(self) -> str:
        return (
            f"<Case {self.name!r}: {len(self.bodies)} bodies, {len(self.joints)} joints, "
            f"{len(self.actuators)} actuators, Dmax {self.dmax}>"
        )


def load_case(source: Union[PathLike, Mapping[str, Any]]) -> Case:
    """A case from a file path or from a dict."""
    if isinstance(source, Mapping):
        return Case.from_dict(source)
    return Case.from_file(source)


def import_urdf(path: PathLike, base: Optional[str] = None, tip: Optional[str] = None) -> Case:
    """A case from a URDF robot description, as ``counterpoise import-urdf`` writes it."""
    path = os.fspath(path)
    urdf = _read(path)
    return Case(_counterpoise.import_urdf(urdf, path, base, tip), path + " (imported)")


def _read(path: str) -> str:
    """A text file's contents, or CounterpoiseError naming the file (as the CLI does)."""
    try:
        with open(path, encoding="utf-8") as f:
            return f.read()
    except OSError as e:
        raise CounterpoiseError(f"cannot read {path}: {e.strerror}") from e
