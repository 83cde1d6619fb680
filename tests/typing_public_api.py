"""Static checks of the public API's types (run by mypy in .ci/run, never called at run time).

Each ``assert_type`` fails the mypy step when an annotation of a name of ``ccproof.__all__`` regresses
(an overload lost, a return type widened to Any or object, the lazy names no longer visible to mypy).
"""

from __future__ import annotations

from typing import Any, assert_type

import numpy as np
from numpy.typing import NDArray

import ccproof
from ccproof.apps.arap.core import MethodResult
from ccproof.apps.dynamics.fit import FitResult
from ccproof.evaluate import PatchTable
from ccproof.evaluate.loop import LoopSurface
from ccproof.evaluate.surface import LimitSurface
from ccproof.reparam.surface import Parameterization
from ccproof.tables.numeric import CharacteristicTable

F64 = NDArray[np.float64]


def _public_api_types(quad: ccproof.QuadMesh, poly: ccproof.PolyMesh) -> None:
    v = ccproof.parse_valence(">=40")
    assert_type(v, ccproof.Valence)
    assert_type(ccproof.Valence.parse({"min": 40}).to_json(), int | dict[str, int])
    assert_type(ccproof.load_table(5), CharacteristicTable)
    assert_type(ccproof.build_table(v), dict[str, Any])
    assert_type(ccproof.prove_valence(5), dict[str, Any])
    assert_type(ccproof.prove_interval(40), dict[str, Any])
    assert_type(ccproof.prove_c1(">=40"), dict[str, Any])
    assert_type(ccproof.characteristic_map(5, [0.5], [0.25]), tuple[F64, F64])
    assert_type(ccproof.characteristic_map(5, [0.5], [0.25], jacobian=True), tuple[F64, F64, F64])
    assert_type(ccproof.inverse_characteristic_map(5, [0.5], [0.25]), tuple[F64, F64])
    assert_type(ccproof.limit_surface(quad), LimitSurface)
    assert_type(ccproof.limit_surface("mesh.obj", alpha=2.5), LimitSurface)
    assert_type(ccproof.limit_surface(poly), LimitSurface)
    assert_type(ccproof.limit_surface(poly, scheme="loop"), LoopSurface)
    assert_type(ccproof.parameterize(quad, variant="boundary"), MethodResult)
    assert_type(ccproof.fit_points(np.zeros((10, 3)), levels=0), FitResult)
    assert_type(ccproof.limit_surface(quad), ccproof.LimitSurface)
    assert_type(ccproof.LimitSurface(poly), LimitSurface)
    assert_type(ccproof.Parameterization("vanishing", 2.5), Parameterization)
    assert_type(ccproof.Parameterization("characteristic").kind, str)
    assert_type(ccproof.PatchTable, type[PatchTable])
    assert_type(ccproof.evaluate.PatchTable, type[PatchTable])
