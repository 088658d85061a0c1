"""Circular coordinates from an H1 cocycle: integer lift, least squares, ``w mod 1``.

Given a cocycle ``z`` over Z/p that represents a persistent class alive at scale
``eps``, the edges of the Rips complex at ``eps`` form a graph; ``z`` is lifted to integer
values (centred in ``(-p/2, p/2]``), checked to be a cocycle on every triangle that
touches its support, and smoothed by the least-squares problem
``argmin_w ||z + δw||₂`` (de Silva, Morozov, Vejdemo-Johansson 2011).  The smoothed
cocycle ``z + δw`` is the harmonic representative; ``-w mod 1`` is a map to the circle
whose increments along edges follow ``z``.  The coordinate is oriented to increase with
frame order and rotated so the first frame sits at 0.

The cochain steps and the extension to every frame live in the private
``periodic._cochain``; this module holds the estimator and re-exports them.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .._blas import one_blas_thread
from ._rips import DENSE_BYTES_PER_PAIR
from .barcode import (
    DEFAULT_PRIME,
    REFINE_BYTES_PER_EDGE,
    Barcode,
    BarSelection,
    check_prime,
    compute_barcode,
    default_max_scale,
    refine_birth,
    select_bar,
    temporal_distance_matrix,
)
from ..errors import ParameterError
from ._cochain import (
    CocycleCheck,
    check_cocycle,
    cocycle_on_edges,
    extend_coordinate,
    harmonic_coordinate,
    lift_cocycle,
    mod_one,
    orient_with_time,
    rips_edges,
    unwrap,
)
from ._estimator import ParamsMixin
from .landmarks import choose_landmarks, estimate_complex, memory_budget, run_bytes

__all__ = [
    "CircularCoordinates",
    "CocycleCheck",
    "rips_edges",
    "lift_cocycle",
    "check_cocycle",
    "harmonic_coordinate",
    "orient_with_time",
    "extend_coordinate",
    "unwrap",
    "RETRY_PRIMES",
]

#: Primes tried, in order, when a cocycle's integer lift fails the cocycle condition.
RETRY_PRIMES = (47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97)


class CircularCoordinates(ParamsMixin):
    """Circle-valued coordinate of a point cloud from its persistent cohomology.

    scikit-learn style estimator: every parameter of ``__init__`` is stored unchanged
    under its own name (``get_params``/``set_params``/``repr`` from
    :class:`~cyclecoord.periodic._estimator.ParamsMixin`, so :func:`sklearn.base.clone`
    works) and checked when fitting; :meth:`fit` computes the barcode, chooses a class
    and a scale, solves for the coordinate and returns ``self``; learned state lives in
    attributes ending in ``_``.  :meth:`transform` gives the coordinate of points the
    model never saw; :meth:`to_arrays` / :meth:`from_arrays` keep a fitted model.

    The fit runs in two stages, :meth:`fit_barcode` then :meth:`fit_coordinate`, so a
    caller can read several classes of one barcode: :meth:`with_coordinate_params` gives
    a new estimator for another class (or scale) that shares this one's barcode and
    leaves this one as it is.

    There is no ``random_state``: the fit is deterministic.  Its only random draw, the
    pairs of points sampled to estimate the filtration's size for the memory guard
    (:func:`~cyclecoord.periodic.landmarks.estimate_complex`), is seeded with 0, the
    package's one ``random_state`` default (as :func:`cyclecoord.extract` and
    :class:`~cyclecoord.periodic.density.PeriodicDensity`).

    Parameters
    ----------
    max_scale : float, optional
        Filtration threshold (see :func:`cyclecoord.periodic.barcode.default_max_scale`).
    scale : float, optional
        Scale at which the cocycle is read; default is high inside the bar.
    class_index : int, default 0
        Which H1 class, by decreasing persistence.
    prime : int, default 47
        Coefficient field; a prime greater than 11.
    scale_fraction : float, default 0.9
        Where in the bar the default scale sits (0 = birth, 1 = death).
    temporal : bool, default False
        Use the time-aware metric where consecutive frames are at distance 0.
    landmarks : "auto", int or None, default "auto"
        Build the filtration on greedy max-min landmarks and extend the coordinate to
        every point (see :func:`cyclecoord.periodic.landmarks.choose_landmarks`).  ``None`` uses
        every point.
    memory_limit : float, optional
        Bytes the fit's large arrays may take: the per-point arrays
        (:func:`~cyclecoord.periodic.landmarks.run_bytes`, plus ``memory_reserved``) and
        the filtration, whose landmarks are chosen (fewer if needed) to fit what is left.
        Default: 2 GiB for the filtration alone.  Never more than the machine holds
        (:func:`~cyclecoord.periodic.landmarks.machine_memory`); a fit whose per-point
        arrays cannot fit is refused before anything is allocated.
    memory_reserved : float, default 0
        Bytes of the caller's own per-frame arrays to count against ``memory_limit``
        (:func:`cyclecoord.extract` passes its poses).
    refine_birth : bool, default True
        With landmarks, also compute the class's birth on every point when cheap.

    Attributes
    ----------
    barcode_ : Barcode
        On the landmarks when they are used.
    selection_ : BarSelection
    prime_ : int
        The prime finally used (another is tried if the lift fails the cocycle check).
    landmarks_ : ndarray of int or None
        Indices of the landmark points (``None``: every point).
    landmark_reason_ : str
        Why that many points were used (memory guard decisions are stated here).
    complex_estimate_ : ComplexEstimate
        Size estimate of the filtration that was built.
    covering_radius_ : float
        Largest distance from a point to its nearest landmark (0 without landmarks).
    edges_ : ndarray, shape (E, 2)
        Rips edges at the chosen scale between the centers (landmarks or all points).
    cocycle_ : ndarray, shape (E,)
        Integer-lifted cocycle on ``edges_``.
    harmonic_cocycle_ : ndarray, shape (E,)
        Its harmonic (least-squares) representative.
    cocycle_check_ : CocycleCheck
    coordinates_ : ndarray, shape (T,)
        Circular coordinate of the training points, in [0, 1), increasing with their
        order, 0 at the first point.
    n_components_ : int
        Connected components of the graph at the chosen scale (1 is expected).
    """

    def __init__(
        self,
        max_scale: float | None = None,
        scale: float | None = None,
        class_index: int = 0,
        prime: int = DEFAULT_PRIME,
        scale_fraction: float = 0.9,
        temporal: bool = False,
        landmarks: int | str | None = "auto",
        memory_limit: float | None = None,
        refine_birth: bool = True,
        memory_reserved: float = 0.0,
    ) -> None:
        self.max_scale = max_scale
        self.scale = scale
        self.class_index = class_index
        self.prime = prime
        self.scale_fraction = scale_fraction
        self.temporal = temporal
        self.landmarks = landmarks
        self.memory_limit = memory_limit
        self.refine_birth = refine_birth
        self.memory_reserved = memory_reserved

    # ------------------------------------------------------------------
    def _validate(self, X) -> np.ndarray:
        x = np.asarray(X, dtype=float)
        if x.ndim != 2:
            raise ParameterError(f"expected a (T, K) array of points, got shape {x.shape}")
        if x.shape[0] < 3:
            raise ParameterError(f"need at least 3 points, got {x.shape[0]}")
        if not np.all(np.isfinite(x)):
            raise ParameterError("points contain NaN or infinite values")
        return x

    def _barcode(self, prime: int) -> Barcode:
        src = self._dist_ if self.temporal else self.points_
        return compute_barcode(
            src,
            max_scale=self.threshold_,
            prime=prime,
            distance_matrix=self.temporal,
            n_landmarks=self.n_landmarks_,
        )

    @one_blas_thread
    def fit_barcode(self, X) -> Barcode:
        """Compute (only) the barcode; sets ``barcode_`` and returns it.

        Chooses the threshold and the number of points first (memory guard).
        """
        x = self._validate(X)
        self.points_ = x
        T, K = x.shape
        reserved = run_bytes(T, K) + float(self.memory_reserved or 0.0)
        budget, note = memory_budget(self.memory_limit, reserved, f"{T} frames of {K} dimensions")
        self.memory_budget_ = budget
        if self.temporal:
            # the (T, T) matrix, then the filtration's copies of it
            need = (8.0 + DENSE_BYTES_PER_PAIR) * T**2
            if need > budget:
                raise ParameterError(
                    f"the temporal metric needs a full {T} x {T} "
                    f"distance matrix ({need / 1e9:.1f} GB, over the "
                    f"{note}); drop --temporal or analyse fewer frames"
                )
            self._dist_ = temporal_distance_matrix(x)
        else:
            self._dist_ = None
        self.threshold_ = float(
            self.max_scale if self.max_scale is not None else default_max_scale(x, self._dist_)
        )
        n, est, reason = choose_landmarks(x, self.threshold_, self.landmarks, budget)
        self.n_landmarks_ = n
        self.complex_estimate_ = est
        self._complex_deferred = est is None  # computed on first access (report)
        self.landmark_reason_ = reason
        self.barcode_ = self._stage_barcode = self._barcode(check_prime(self.prime))
        self.landmarks_ = self.barcode_.point_indices
        self.covering_radius_ = float(self.barcode_.extras.get("covering_radius", 0.0))
        return self.barcode_

    @property
    def complex_estimate_(self):
        """Size estimate of the filtration that was built (computed when first asked
        for if the memory guard did not need it)."""
        if getattr(self, "_complex_deferred", False):
            self._complex_estimate = estimate_complex(
                self.points_, self.threshold_, n_vertices=self.n_landmarks_
            )
            self._complex_deferred = False
        return self._complex_estimate

    @complex_estimate_.setter
    def complex_estimate_(self, value) -> None:
        self._complex_estimate = value
        self._complex_deferred = False

    def use_barcode(self, X, barcode: Barcode) -> "CircularCoordinates":
        """Adopt a barcode already computed on every point of ``X`` (Euclidean metric).

        Skips the threshold choice and the memory guard of :meth:`fit_barcode`; meant for
        many small point clouds (the windows of :func:`cyclecoord.detect`) whose barcode
        the caller has computed and screened itself.  Call :meth:`fit_coordinate` next.

        Parameters
        ----------
        X : array-like, shape (T, K)
            The points the barcode was computed on, in frame order.
        barcode : Barcode
            Full (landmark-free) barcode of ``X``.
        """
        x = self._validate(X)
        if barcode.point_indices is not None or barcode.n_points != len(x):
            raise ParameterError("use_barcode() needs a barcode on every point of X (no landmarks)")
        if self.temporal:
            raise ParameterError("use_barcode() works with the Euclidean metric only")
        self.points_ = x
        self._dist_ = None
        self.threshold_ = float(barcode.threshold)
        self.n_landmarks_ = None
        self.complex_estimate_ = None
        self.landmark_reason_ = "every frame (barcode supplied)"
        self.barcode_ = self._stage_barcode = barcode
        self.landmarks_ = None
        self.covering_radius_ = 0.0
        return self

    def fit(self, X, y=None) -> "CircularCoordinates":
        """Barcode, class and scale selection, cocycle check and the coordinate.

        Parameters
        ----------
        X : array-like, shape (T, K)
            Points (one per frame, in frame order: the orientation follows it).
        y : None
            Ignored (scikit-learn convention).

        Returns
        -------
        CircularCoordinates
            ``self``, fitted.
        """
        self.fit_barcode(X)
        return self.fit_coordinate()

    #: Parameters used only by :meth:`fit_coordinate` (the barcode does not depend on them).
    COORDINATE_PARAMS = ("class_index", "scale", "scale_fraction", "refine_birth")
    #: Fitted state of the barcode stage, shared by :meth:`with_coordinate_params`.
    _BARCODE_STATE = (
        "points_", "_dist_", "memory_budget_", "threshold_", "n_landmarks_", "_complex_estimate",
        "_complex_deferred", "landmark_reason_", "_stage_barcode", "landmarks_", "covering_radius_",
    )

    def with_coordinate_params(self, **params) -> "CircularCoordinates":
        """A new estimator with coordinate parameters changed, on this one's barcode.

        The new estimator is built from this one's parameters with ``params`` replacing
        some of them, and shares (does not copy, does not recompute) the barcode stage of
        this one (the points, threshold, landmarks and barcode of :meth:`fit_barcode` or
        :meth:`use_barcode`); call :meth:`fit_coordinate` on it next.  This estimator is
        not changed, so one barcode can be read for several classes at the cost of the
        coordinates alone (:func:`cyclecoord.detect` reads every candidate class so).

        Parameters
        ----------
        **params
            Any of :data:`COORDINATE_PARAMS` (``class_index``, ``scale``,
            ``scale_fraction``, ``refine_birth``).

        Returns
        -------
        CircularCoordinates
            Ready for :meth:`fit_coordinate`.

        Raises
        ------
        ParameterError
            When this estimator has no barcode yet, or for a parameter the barcode
            depends on (set it on a clone and fit that instead).
        """
        if not hasattr(self, "_stage_barcode"):
            raise ParameterError(
                "call fit_barcode() or use_barcode() before with_coordinate_params()"
            )
        other = sorted(set(params) - set(self.COORDINATE_PARAMS))
        if other:
            raise ParameterError(
                f"with_coordinate_params() changes {', '.join(self.COORDINATE_PARAMS)} only; "
                f"the barcode depends on {', '.join(other)}"
            )
        new = type(self)(**{**self.get_params(deep=False), **params})
        for name in self._BARCODE_STATE:
            if name in self.__dict__:
                setattr(new, name, self.__dict__[name])
        new.barcode_ = new._stage_barcode
        return new

    def _centers(self) -> tuple[np.ndarray, np.ndarray | None]:
        """Points the complex is built on, and (for the temporal metric) their distances."""
        if self.landmarks_ is None:
            return self.points_, self._dist_
        idx = self.landmarks_
        dist = self._dist_[np.ix_(idx, idx)] if self._dist_ is not None else None
        return self.points_[idx], dist

    def _cocycle_on_centers(self, cocycle: np.ndarray) -> np.ndarray:
        """Cocycle rows with point indices mapped to center positions, oriented ``i < j``."""
        if self.landmarks_ is None:
            return cocycle
        inv = np.full(len(self.points_), -1, dtype=np.int64)
        inv[self.landmarks_] = np.arange(len(self.landmarks_))
        c = cocycle.copy()
        c[:, 0], c[:, 1] = inv[cocycle[:, 0]], inv[cocycle[:, 1]]
        swap = c[:, 0] > c[:, 1]
        c[swap, 0], c[swap, 1] = c[swap, 1], c[swap, 0].copy()
        c[swap, 2] = -c[swap, 2]
        return c

    @one_blas_thread
    def fit_coordinate(self) -> "CircularCoordinates":
        """Second half of :meth:`fit`: select the class and solve for the coordinate,
        reusing the barcode from :meth:`fit_barcode` (so a caller can inspect the
        barcode first without computing it twice)."""
        if not hasattr(self, "_stage_barcode"):
            raise ParameterError("call fit_barcode() before fit_coordinate()")
        # the barcode of the barcode stage, not barcode_: a prime retry below replaces
        # barcode_, and a second call (another class_index) must index the same bars
        barcode = self._stage_barcode
        selection = select_bar(barcode, self.class_index, self.scale, self.scale_fraction)
        notes = []
        scale = selection.scale
        if self.landmarks_ is not None and scale < 2.0 * self.covering_radius_ * 1.02:
            # the landmark balls (radius scale/2) must cover every point
            wanted = 2.0 * self.covering_radius_ * 1.02
            top = min(selection.death, barcode.threshold)
            if wanted < top:
                scale = wanted
                notes.append(
                    f"scale raised to {scale:.4g} so the landmark balls cover every frame "
                    f"(covering radius {self.covering_radius_:.4g})"
                )
            else:
                notes.append(
                    f"the landmark covering radius {self.covering_radius_:.4g} exceeds half the "
                    "bar's extent: frames far from every landmark take their nearest landmark's "
                    "coordinate; use more landmarks"
                )
        selection = BarSelection(**{**selection.__dict__, "scale": float(scale)})
        centers, cdist = self._centers()
        n = len(centers)
        edges = rips_edges(centers, selection.scale, cdist)
        # Lift and check; when the lift is not an integer cocycle, retry with other primes.
        tried = []
        best = None
        primes = [barcode.prime] + [p for p in RETRY_PRIMES if p != barcode.prime]
        for k, p in enumerate(primes):
            if k == 0:
                bc, sel = barcode, selection
            else:
                bc = self._barcode(p)
                if len(bc.h1) == 0:
                    continue
                # the same class: nearest bar in (birth, capped death)
                cap = np.minimum(bc.h1[:, 1], bc.threshold)
                ref = (selection.birth, min(selection.death, barcode.threshold))
                idx = int(np.argmin(np.abs(bc.h1[:, 0] - ref[0]) + np.abs(cap - ref[1])))
                b, d = bc.h1[idx]
                if not b <= selection.scale < d:
                    continue
                sel = BarSelection(
                    **{**selection.__dict__, "index": idx, "birth": float(b), "death": float(d)}
                )
            cocycle = self._cocycle_on_centers(bc.cocycles[sel.index])
            z, outside = cocycle_on_edges(edges, cocycle, lift_cocycle(cocycle, p).astype(float), n)
            check = check_cocycle(edges, z, n)
            check = CocycleCheck(check.n_triangles, check.n_violations, outside)
            tried.append((p, check.n_violations))
            if best is None or check.n_violations < best[3].n_violations:
                best = (p, bc, sel, check, z)
            if check.ok:
                break
        p, bc, sel, check, z = best
        # stacklevel 3: past the one_blas_thread wrapper, to the caller of fit_coordinate
        if not check.ok:
            warnings.warn(
                "the integer lift of the cocycle fails the cocycle "
                f"condition on {check.n_violations} of {check.n_triangles} "
                f"triangles for every prime tried; using p={p}",
                RuntimeWarning,
                stacklevel=3,
            )
        for note in notes:
            warnings.warn(note, RuntimeWarning, stacklevel=3)
        ncomp, _ = connected_components(
            sp.csr_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n)),
            directed=False,
        )
        if self.landmarks_ is None:
            weights = None
        else:
            # each landmark stands for the frames nearest to it
            _, owner = cKDTree(centers).query(self.points_, k=1)
            mass = np.bincount(np.asarray(owner).ravel(), minlength=n).astype(float)
            mass = np.maximum(mass, 1.0)
            weights = mass[edges[:, 0]] * mass[edges[:, 1]]
        center_theta, harmonic = harmonic_coordinate(edges, z, n, weights)
        if self.landmarks_ is None:
            raw = center_theta
            covered = np.ones(n, dtype=bool)
        else:
            raw, covered = extend_coordinate(
                self.points_, centers, center_theta, edges, harmonic, selection.scale / 2.0
            )
        theta, sign, offset = orient_with_time(raw, return_transform=True)
        if self.landmarks_ is not None and not self.temporal and self.refine_birth:
            # the sparse complex within what the filtration was allowed (it is gone by now)
            budget = getattr(self, "memory_budget_", None)
            max_edges = (
                3_000_000 if budget is None else int(min(3_000_000, budget / REFINE_BYTES_PER_EDGE))
            )
            full = (refine_birth(self.points_, sel.birth, p, max_edges=max_edges,
                                 covering_radius=self.covering_radius_) if max_edges > 0 else None)
            sel = BarSelection(**{**sel.__dict__, "full_birth": full})
        self.barcode_ = bc
        self.selection_ = sel
        self.prime_ = p
        self.primes_tried_ = tried
        self.edges_ = edges
        self.cocycle_ = z
        self.harmonic_cocycle_ = harmonic
        self.cocycle_check_ = check
        self.n_components_ = int(ncomp)
        self.coordinates_ = theta
        self.covered_ = covered
        self.centers_ = centers
        self.center_theta_ = center_theta
        self.radius_ = selection.scale / 2.0
        self.orientation_ = (sign, offset)
        return self

    def _check_fitted(self) -> None:
        if not hasattr(self, "center_theta_"):
            raise ParameterError("this CircularCoordinates is not fitted yet; call fit() first")

    def transform(self, X) -> np.ndarray:
        """Circular coordinate of points, in the fitted model's orientation.

        The training points get their fitted coordinate; other points are placed by the
        partition-of-unity extension (:func:`extend_coordinate`) over the balls of radius
        ``scale / 2`` around the centers (landmarks, or all training points).
        """
        self._check_fitted()
        x = self._validate(X)
        if (
            hasattr(self, "points_")
            and x.shape == self.points_.shape
            and np.array_equal(x, self.points_)
        ):
            return self.coordinates_.copy()
        if x.shape[1] != self.centers_.shape[1]:
            raise ParameterError(
                f"points have {x.shape[1]} dimensions, the model was fitted on "
                f"{self.centers_.shape[1]}"
            )
        raw, _ = extend_coordinate(
            x, self.centers_, self.center_theta_, self.edges_, self.harmonic_cocycle_, self.radius_
        )
        sign, offset = self.orientation_
        return mod_one(sign * raw - offset)

    def fit_transform(self, X, y=None) -> np.ndarray:
        return self.fit(X).coordinates_.copy()

    # ------------------------------------------------------------------ persistence
    _SAVED = ("centers_", "center_theta_", "edges_", "harmonic_cocycle_")

    def to_arrays(self) -> dict:
        """The fitted state needed by :meth:`transform`, as plain arrays."""
        self._check_fitted()
        out = {k.rstrip("_"): getattr(self, k) for k in self._SAVED}
        out["radius"] = np.array(self.radius_)
        out["orientation"] = np.array(self.orientation_, dtype=float)
        out["selection"] = np.array(
            [
                self.selection_.index,
                self.selection_.birth,
                self.selection_.death,
                self.selection_.scale,
            ]
        )
        out["prime"] = np.array(self.prime_)
        return out

    @classmethod
    def from_arrays(cls, arrays: dict) -> "CircularCoordinates":
        """Rebuild a fitted model from :meth:`to_arrays` output (transform only)."""
        est = cls()
        try:
            for k in cls._SAVED:
                setattr(est, k, np.asarray(arrays[k.rstrip("_")]))
            est.radius_ = float(arrays["radius"])
            sign, offset = (float(v) for v in arrays["orientation"])
            est.orientation_ = (sign, offset)
            idx, b, d, s = (float(v) for v in arrays["selection"])
            est.prime_ = int(arrays["prime"])
        except KeyError as exc:
            raise ParameterError(f"model data lacks {exc.args[0]!r}") from None
        est.selection_ = BarSelection(int(idx), b, d, s, True, float("nan"), float("nan"))
        return est
