"""Irradiance on a bus roof: direct (ray-cast), diffuse and reflected light.

The paper's model (sections 3.2.1 to 3.2.3), extended for streets:

* (1) direct    ``E_b = DNI x max(cos AOI, 0) x V_sun`` with ``V_sun`` = 1 when the ray
  from the roof point to the sun is not blocked (Embree occlusion query);
* (2) diffuse   the Perez (1993) sky's light over the sky the roof point sees
  (``diffuse_model: perez_svf``, the default; :mod:`vipvflow.models.sky`), or
  ``E_d = DHI x SVF`` with the cosine-weighted sky view factor of the roof point
  (``sky_view_factor``, a uniform sky), or the paper's isotropic sky
  ``E_d = DHI x (1 + cos beta) / 2`` (Liu & Jordan; pvlib ``irradiance.isotropic``;
  ``diffuse_model: isotropic``), which counts the sky the buildings hide as open: an upper
  bound in streets;
* (3) reflected: every surface seen from the roof reflects (Lambertian) the irradiance it
  receives, weighted by its view factor.  The surfaces seen are found once per segment with
  cosine-weighted rays (4x more where the sky view factor is below 0.75) and merged into a
  few reflector groups by orientation; the street those groups see is one more reflector.
  Each keeps P sample points (``reflector_points``) and its own view factors of sky, street,
  facades and open ground beyond the mesh.  Per pass a reflector ``j`` receives
  ``S_j = DNI max(cos theta_j, 0) L_j + DHI F_s,j + GHI rho_g F_o,j``, ``L_j`` the sunlit
  fraction of its sample points: by default (``reflector_sampling: rotate``) one point per
  pass, taken in turn by a hash of segment and time, counts as 0 or 1, so the mean over a
  segment's passes is the P-point fraction with one ray per reflector instead of P;
  ``all`` traces every point every pass (one sun at a time: the Radiance cross-check).
  The light the reflectors pass to each other (street to facade, facade to facade) is the
  radiosity solution of these few surfaces, folded into one weight per reflector
  (:func:`_exchange_weights`).  The sample points are stratified over each reflector in
  two dimensions (:func:`_group_points`: 64 points, 8 x 8 strata of height and position
  along a facade).  Against Radiance ``-ab 8`` in two street canyons at 12 instants of
  2024 the total is within 5.5 % and the reflected part within 13 % at every one of the
  84 point-instants, and within 20 % for other seeds (docs/reflection_sampling.md).

:func:`roof_components` is the one place the components are summed (the simulation and the
web app call it); :func:`vipvflow.models.loss.shading_loss` the one shading-loss formula.

Roof plane: tilt ``beta = atan(|gradient|)``, facing downhill (a bus climbing tilts its roof
backwards), azimuth from the heading.  All angles in degrees at the interfaces, azimuths
clockwise from north; irradiances in W/m2; coordinates in metres (x east, y north, z up).

References
----------
B. Y. H. Liu, R. C. Jordan (1963), The long-term average performance of flat-plate solar
energy collectors, Solar Energy 7(2), 53-74.  T. R. Oke (1988), Street design and urban
canopy layer climate, Energy and Buildings 11, 103-113.  pvlib:
``pvlib.irradiance.get_total_irradiance`` (``model='isotropic'``), ``pvlib.irradiance.aoi``.
"""
from __future__ import annotations

import time

import numpy as np
import pandas as pd

from .params import IrradianceCfg
from .sky import COS_85
from .trees import month_of
from .view_factors import _CHUNK, COMPONENTS, isotropic_sky_view, pack_geometry


def _finite(x) -> np.ndarray:
    """*x* as float32 with NaN (outside the radiation grid) as 0; no copy when clean."""
    x = np.asarray(x, np.float32)
    bad = np.isnan(x)
    return np.where(bad, np.float32(0), x) if bad.any() else x


def _local_frame(geo: dict, scene) -> bool:
    """Whether *geo* holds ray origins in the frame of *scene* (see :func:`pack_geometry`)."""
    o = geo.get("scene_origin")
    return o is not None and hasattr(scene, "occluded_local") and np.array_equal(o, scene.origin)


def roof_components(dni_wm2, dhi_wm2, ghi_wm2, cos_aoi, sun_visible, sky_view,
                    reflector_beam, reflector_lit, reflector_sky, reflector_ghi,
                    isotropic_view, sky=None):
    """Direct, diffuse and reflected irradiance on the roof from what the roof point sees
    (eqs. 1-3): the one place the components are summed, for the simulation (visibility
    from ray casting) and the web app (visibility from stored horizon profiles).

    Parameters
    ----------
    dni_wm2, dhi_wm2, ghi_wm2 : (n,) direct normal, diffuse horizontal and global horizontal
        irradiance, W/m2
    cos_aoi : (n,) cosine of the sun's angle of incidence on the roof, clipped at 0
    sun_visible : (n,) 1 (or True) when the ray from the roof point to the sun is free, else 0
    sky_view : (n,) sky view factor of the roof for the diffuse sky: ``(1 + cos tilt) / 2``
        (isotropic, the paper) or the cosine-weighted sky view factor of the roof point
        (Oke's canyon SVF; ``diffuse_model: sky_view_factor`` and ``perez_svf``)
    reflector_beam : (n, J) per reflector ``j``: its weight at the roof (albedo x view factor,
        inter-reflections folded in, see :func:`pack_geometry`) x the cosine of the sun on it,
        clipped at 0; dimensionless
    reflector_lit : (n, J) sunlit fraction of each reflector's sample points (0..1); a
        caller that has already summed ``weight x cos x lit`` over its reflectors (the
        kernel, from sparse pairs) passes that sum as one column with ``lit = 1``
    reflector_sky, reflector_ghi : (n,) the reflectors' weight of DHI (their own sky views)
        and of GHI (open ground beyond the city model, lit as an open field); dimensionless
    isotropic_view : (n,) ``(1 + cos tilt) / 2`` (:func:`isotropic_sky_view`), for the
        unshaded reference
    sky : dict, optional
        The Perez sky (``diffuse_model: perez_svf``; none: a uniform sky), (n,) arrays:
        ``f1, f2`` the circumsolar and horizon coefficients (:mod:`vipvflow.models.sky`),
        ``cos_zenith`` of the sun, ``horizon_view`` the roof point's view of the horizon
        band, ``reflector_horizon`` the reflectors' so weighted (:func:`pack_geometry`),
        ``sin_tilt`` of the roof (the open field's horizon view, for the unshaded reference)
        and, optionally, ``share``: the share of DHI the roof point receives from the Perez
        (1993) sky luminance over the sky it sees (:meth:`RadiationTable.sky_share`), which
        then is its diffuse light instead of the three parts below, and ``share_open`` the
        same in the open (the unshaded reference's).

    Returns
    -------
    direct_wm2, diffuse_wm2, reflected_wm2, unshaded_wm2 : (n,) arrays, W/m2; unshaded is
    the open-field plane-of-array irradiance ``DNI cos AOI + E_sky`` (no buildings, no
    ground reflection; ``E_sky = DHI (1 + cos tilt) / 2``, or pvlib's Perez sky diffuse under
    the Perez sky), the reference of :func:`~vipvflow.models.loss.shading_loss`.

    Notes
    -----
    With ``share`` (the run's ``perez_svf``) the roof's diffuse light is ``DHI x share``:
    the sky's luminance (Perez, Seals, Michalsky 1993, as Radiance's ``gendaylit``)
    integrated over the sky above the roof point's horizon; without it, the three-part form
    of the Perez (1990) model.  Under the Perez sky (Perez et al. 1990, pvlib
    ``irradiance.perez``) the three-part diffuse light is ``DHI [(1 - F1) SVF + F2 H] + C cos AOI V_sun`` with ``C = DHI F1 / max(cos Z, cos 85
    deg)`` the circumsolar irradiance at normal incidence: the circumsolar part is seen
    when, and only when, the sun is (it travels the sun ray), the isotropic part by the sky
    view factor and the horizon part by the horizon-band view ``H``.  The reflectors are lit
    the same way: their beam is ``DNI + C`` on their sunlit part, their sky ``DHI [(1 - F1)
    F_s + F2 H_j]``.  The diffuse part is clipped at 0 as pvlib clips the sky diffuse.

    References
    ----------
    B. Y. H. Liu, R. C. Jordan (1963), The long-term average performance of flat-plate
    solar energy collectors, Solar Energy 7(2), 53-74.
    T. R. Oke (1988), Street design and urban canopy layer climate, Energy and Buildings 11,
    103-113 (sky view factor of a street canyon).
    R. Perez, P. Ineichen, R. Seals, J. Michalsky, R. Stewart (1990), Modeling daylight
    availability and irradiance components from direct and global irradiance, Solar Energy
    44(5), 271-289.
    pvlib: ``irradiance.get_total_irradiance(model='isotropic')``, ``irradiance.perez``,
    ``irradiance.aoi``.
    """
    f32 = np.float32
    beam_on_roof = dni_wm2 * cos_aoi
    direct = beam_on_roof * sun_visible
    beam_factor = np.einsum("ij,ij->i", reflector_beam, reflector_lit) if np.shape(reflector_beam)[-1] \
        else np.zeros_like(direct)
    if sky is None:
        diffuse = dhi_wm2 * sky_view
        reflected = dni_wm2 * beam_factor + dhi_wm2 * reflector_sky + ghi_wm2 * reflector_ghi
        return direct, diffuse, reflected, beam_on_roof + dhi_wm2 * isotropic_view
    f1, f2 = sky["f1"], sky["f2"]
    circumsolar = dhi_wm2 * f1 / np.maximum(sky["cos_zenith"], f32(COS_85))
    circ_on_roof = circumsolar * cos_aoi
    iso = f32(1) - f1
    if "share" in sky:
        diffuse = np.maximum(dhi_wm2 * sky["share"], f32(0))
    else:
        diffuse = np.maximum(dhi_wm2 * (iso * sky_view + f2 * sky["horizon_view"])
                             + circ_on_roof * sun_visible, f32(0))
    reflected = ((dni_wm2 + circumsolar) * beam_factor
                 + dhi_wm2 * (iso * reflector_sky + f2 * sky["reflector_horizon"])
                 + ghi_wm2 * reflector_ghi)
    if "share" in sky:
        unshaded = beam_on_roof + np.maximum(dhi_wm2 * sky["share_open"], f32(0))
    else:
        unshaded = beam_on_roof + np.maximum(dhi_wm2 * (iso * isotropic_view + f2 * sky["sin_tilt"])
                                             + circ_on_roof, f32(0))
    return direct, diffuse, reflected, unshaded


#: reflectors weighing less than this at the roof (weight x cos of the sun on them) are
#: traced in ``rotate`` sampling with probability weight / this, and then count this much
#: (Russian roulette: unbiased, fewer rays for the faint ones)
ROULETTE_WEIGHT = 0.02


def _roulette(pi, gi, weight, key):
    """Which (pass, reflector) pairs cast their ray, and the beam weight each then carries.

    Pairs of weight >= :data:`ROULETTE_WEIGHT` always do, with their weight; fainter ones
    with probability ``weight / ROULETTE_WEIGHT`` (a uniform from the pass's sample key and
    the reflector, independent of the sample point taken in turn) and carry
    ``ROULETTE_WEIGHT``: the expected beam is unchanged.
    """
    small = np.flatnonzero(weight < ROULETTE_WEIGHT)
    if not len(small):
        return pi, gi, weight
    k = (key[pi[small]] >> 4) * 0x2545F491 + gi[small] * 0x9E3779B1
    u = ((k ^ (k >> 29)) & 0xFFFFFF).astype(np.float32) * np.float32(1.0 / (1 << 24))
    keep = np.ones(len(pi), bool)
    keep[small] = u * np.float32(ROULETTE_WEIGHT) < weight[small]
    return pi[keep], gi[keep], np.maximum(weight[keep], np.float32(ROULETTE_WEIGHT))


def roof_irradiance(geometry, rows, sun: np.ndarray, rad: dict, scene, cfg: IrradianceCfg,
                    ground_albedo: float = 0.20, sample=None, timings: dict | None = None,
                    month=None) -> dict:
    """Irradiance components for arrays of passes (the hot path), eqs. (1)-(3).

    Parameters
    ----------
    geometry : DataFrame from :func:`segment_geometry`, or its :func:`pack_geometry`
    rows : (n,) int, row of *geometry* for each pass
    sun : (n, 3) float32, unit vector towards the sun (east, north, up)
    rad : dict of (n,) arrays ``ghi, dni, dhi, ghi_clear, dni_clear, dhi_clear`` (W/m2);
        under the Perez sky also ``f1, f2`` (and ``_clear``) and, with the geometry's sky
        sectors, ``sky_share, sky_open`` (and ``_clear``), with crowns in the sky
        ``sky_tree`` (and ``_clear``): the share of DHI they take
        (:meth:`RadiationTable.sky_tree_share`)
    scene : vipvflow.models.shading.Scene
    cfg : IrradianceCfg
    ground_albedo : float, albedo of the open ground seen by reflectors (used when packing)
    sample : (n,) int, optional
        With ``cfg.reflector_sampling == 'rotate'``: which of a reflector's P sample
        points each pass traces (reflector ``j`` of pass ``i`` traces point
        ``(sample[i] + j) mod P``); default ``0, 1, 2, ...`` in the order of the passes.
        :func:`evaluate_passes` derives it from a hash of the segment and the time, so it
        does not depend on how passes are batched.
    timings : dict, optional
        Seconds spent are added to its ``ray_setup_s``, ``rays_s`` and ``components_s``
        (the caller times; the kernel keeps no state).
    month : (n,) int, optional, the month (1..12) of each pass: the crowns' class of months
        (:mod:`vipvflow.models.trees`); needed where the geometry has more than one

    Returns
    -------
    dict of (n,) float32 arrays, W/m2: :data:`COMPONENTS` and ``sun_visible`` (bool: the sun
    ray misses the buildings; the crowns it crosses then pass their transmittance of the
    beam).  Rays are cast only with the sun up and a beam in either channel: one per pass
    with the sun in front of the roof, and for every reflector (group or street) facing the
    sun either one ray per sample point (``reflector_sampling: all``: the lit fraction, in
    steps of 1/P without crowns) or one ray from one sample point taken in turn (``rotate``:
    the lit fraction is 0 or the crowns' transmittance for that pass, and its mean over
    passes is the P-point lit fraction, an unbiased estimate with P times fewer rays); all
    in one occlusion query, and the same visibility serves all-sky and clear-sky.  A ray the
    buildings let through is traced through the tile's crowns
    (:meth:`vipvflow.models.trees.Crowns.transmittance`).  The components are summed by
    :func:`roof_components`; ``direct_no_trees`` and ``diffuse_no_trees`` are the direct
    and diffuse light with the buildings alone (all-sky).

    References
    ----------
    The paper (section 3: direct, isotropic diffuse and reflected light on the roof); the
    sky view factor of Oke (J. Climatol. 1, 1981) for the default diffuse model; pvlib
    ``irradiance.get_total_irradiance`` for the unshaded plane of array.
    """
    f32 = np.float32
    t_start = time.perf_counter()
    geo = geometry if isinstance(geometry, dict) else pack_geometry(geometry, cfg, ground_albedo, scene)
    local = _local_frame(geo, scene)
    rows = np.asarray(rows, np.int64)
    sun = np.asarray(sun, f32)
    n = len(rows)
    nrm = geo["n"][rows]
    crowns = scene.crowns(cfg) if hasattr(scene, "crowns") else None
    cls = pass_classes(geo, rows, month)
    dni, dhi, ghi = _finite(rad["dni"]), _finite(rad["dhi"]), _finite(rad["ghi"])
    dnic, dhic, ghic = _finite(rad["dni_clear"]), _finite(rad["dhi_clear"]), _finite(rad["ghi_clear"])
    perez = cfg.diffuse_model == "perez_svf"
    if perez:
        need = ("f1", "f2", "f1_clear", "f2_clear") + (
            ("sky_share", "sky_share_clear", "sky_open", "sky_open_clear")
            if geo["sky_x"].shape[1] else ())
        missing = [c for c in need if c not in rad]
        if missing:
            raise KeyError(f"the Perez sky needs {', '.join(missing)} in the radiation "
                           "(models.sky.perez_coefficients)")
        f1, f2, f1c, f2c = (_finite(rad[c]) for c in ("f1", "f2", "f1_clear", "f2_clear"))
        beam_any = (dni > 0) | (dnic > 0) | (f1 > 0) | (f1c > 0)     # circumsolar is beam-like
    else:
        beam_any = (dni > 0) | (dnic > 0)
    lit = np.flatnonzero((sun[:, 2] > 0) & beam_any)
    sl = sun[lit]
    rows_lit = rows[lit]
    cos_aoi = np.zeros(n, f32)
    cos_aoi[lit] = np.maximum(np.einsum("ij,ij->i", nrm[lit], sl), 0)
    cand = lit[cos_aoi[lit] > 0]
    G = geo["wn"].shape[2] if (cfg.reflection and cfg.max_reflector_groups) else 0
    # reflectors facing the sun: (pass, reflector) pairs, P points each (or one of them,
    # in turn); every ray of the chunk (direct first) goes into one occlusion query
    nd = len(cand)
    gp = geo["group_p_local"] if local else geo["group_p"]
    P = gp.shape[1]
    if G and len(lit):
        wc = np.einsum("igj,ij->ig", geo["wn"][rows_lit, cls[lit]], sl)
        pi, gi = np.nonzero(wc > 0)
    else:
        pi = gi = np.zeros(0, np.int64)
    rotate = cfg.reflector_sampling == "rotate" and P > 1
    if rotate:
        base = np.arange(n, dtype=np.int64) if sample is None else np.asarray(sample, np.int64)
        pi, gi, beam_w = _roulette(pi, gi, wc[pi, gi] if len(pi) else np.zeros(0, f32), base[lit])
    elif len(pi):
        beam_w = wc[pi, gi]
    per_pair = 1 if rotate else P
    nr = nd + per_pair * len(pi)
    visible = np.zeros(n, bool)
    vis_t = np.zeros(n, f32)              # the sun ray's transmittance: 0 or the crowns'
    beam_sum = np.zeros(n, f32)           # sum over reflectors of weight x cos x lit
    if nr:
        o = np.empty((nr, 3), f32 if local else np.float64)
        d = np.empty((nr, 3), f32)
        np.take(geo["p_local"] if local else geo["p"], rows[cand], axis=0, out=o[:nd])
        np.take(sun, cand, axis=0, out=d[:nd])
        if len(pi):
            pair = rows_lit[pi] * G + gi
            if rotate:
                k = (base[lit][pi] + gi) % P
                o[nd:] = gp[pair, k]
                np.take(sl, pi, axis=0, out=d[nd:])
            else:
                np.take(gp, pair, axis=0, out=o[nd:].reshape(-1, P, 3))
                d[nd:].reshape(-1, P, 3)[:] = sl[pi][:, None, :]
        t_rays = time.perf_counter()
        occ = (scene.occluded_local(o, d, cfg.ray_length_m) if local
               else scene.occluded(o, d, cfg.ray_length_m))
        # the crowns along each ray the buildings let through, in its pass's class
        T = (~occ).astype(f32)
        if crowns is not None and nr:
            free = np.flatnonzero(~occ)
            ray_pass = np.empty(nr, np.int64)
            ray_pass[:nd] = cand
            ray_pass[nd:] = np.repeat(lit[pi], per_pair)
            oo = o[free].astype(np.float64) - (0.0 if local else scene.origin)
            T[free] = crowns.transmittance(oo, d[free], cfg.ray_length_m, cls[ray_pass[free]])
        t_done = time.perf_counter()
        _add_seconds(timings, ray_setup_s=t_rays - t_start, rays_s=t_done - t_rays)
        t_start = t_done
        visible[cand] = ~occ[:nd]
        vis_t[cand] = T[:nd]
        if len(pi):
            # each sample point's lit fraction times its factor through the crowns (1
            # without): the reflector as the roof sees it through them (view_factors._group_points)
            gf = geo["group_f"]
            if rotate:
                share = T[nd:] * gf[pair, k, cls[lit[pi]]]
            else:
                share = ((T[nd:].reshape(-1, P) * gf[pair, :, cls[lit[pi]]]).sum(1, dtype=np.float64)
                         * np.float64(f32(1.0 / P)))
            beam_sum[lit] = np.bincount(pi, beam_w * share, len(lit))
    iso = isotropic_sky_view(nrm[:, 2])
    if cfg.diffuse_model != "isotropic":
        sky, sky_nt = geo["svf"][rows, cls], geo["svf_no_trees"][rows]
    else:
        sky = sky_nt = iso
    zero, one = np.zeros(n, f32), np.ones(n, f32)
    r_sky, r_ghi = (geo["refl_sky"][rows, cls], geo["refl_ghi"][rows, cls]) if G else (zero, zero)
    if perez:
        perez_sky = sky_terms(geo, rows, sun[:, 2], G, cls)
    out = {}
    for sfx, (b, dh, gh) in (("", (dni, dhi, ghi)), ("_clear", (dnic, dhic, ghic))):
        terms = None
        if perez:
            terms = {**perez_sky, "f1": f1 if not sfx else f1c, "f2": f2 if not sfx else f2c}
            if geo["sky_x"].shape[1]:
                terms["share"] = _finite(rad["sky_share" + sfx])
                terms["share_open"] = _finite(rad["sky_open" + sfx])
                if "sky_tree" + sfx in rad:
                    terms["share"] = terms["share"] - _finite(rad["sky_tree" + sfx])
        (out["direct" + sfx], out["diffuse" + sfx], out["reflected" + sfx],
         unshaded) = roof_components(b, dh, gh, cos_aoi, vis_t, sky, beam_sum[:, None],
                                     one[:, None], r_sky, r_ghi, iso, terms)
        out["total" + sfx] = out["direct" + sfx] + out["diffuse" + sfx] + out["reflected" + sfx]
        out[f"total{sfx}_unshaded"] = unshaded
    # the buildings alone: the sun ray free of them, the sky without crowns
    terms = None
    if perez:
        terms = {**sky_terms(geo, rows, sun[:, 2], G, cls, trees=False), "f1": f1, "f2": f2}
        if geo["sky_x"].shape[1]:
            terms["share"], terms["share_open"] = _finite(rad["sky_share"]), _finite(rad["sky_open"])
    out["direct_no_trees"], out["diffuse_no_trees"], _, _ = roof_components(
        dni, dhi, ghi, cos_aoi, visible.astype(f32), sky_nt, beam_sum[:, None], one[:, None],
        r_sky, r_ghi, iso, terms)
    out["sun_visible"] = visible
    _add_seconds(timings, components_s=time.perf_counter() - t_start)
    return out


def pass_classes(geo: dict, rows, month=None) -> np.ndarray:
    """Each pass's class of months (int64): the geometry row's class of the pass's *month*
    (1..12; :mod:`vipvflow.models.trees`), 0 where the geometry has one class only."""
    rows = np.asarray(rows, np.int64)
    tm = geo.get("tree_month")
    if tm is None or not len(tm) or not tm.any():
        return np.zeros(len(rows), np.int64)
    if month is None:
        raise ValueError("the geometry has classes of months (tree crowns): give each pass's month")
    return tm[rows, np.asarray(month, np.int64) - 1]


def sky_terms(geo: dict, rows, cos_zenith, with_reflectors: bool = True, classes=None,
              trees: bool = True) -> dict:
    """The per-pass geometry of the Perez sky for :func:`roof_components` (its *sky*
    without ``f1, f2``): the sun's ``cos_zenith``, the roof's ``horizon_view`` and
    ``sin_tilt``, the reflectors' ``reflector_horizon`` (float32, dimensionless).

    Parameters
    ----------
    geo : dict from :func:`pack_geometry`
    rows : (n,) int, rows of *geo*
    cos_zenith : (n,) float, up component of the unit vector towards the sun
    with_reflectors : bool, whether the reflectors count (else their horizon weight is 0)
    classes : (n,) int, optional, each pass's class of months (:func:`pass_classes`; 0)
    trees : bool, the roof's horizon view through the crowns (else without them)
    """
    f32 = np.float32
    rows = np.asarray(rows, np.int64)
    cls = np.zeros(len(rows), np.int64) if classes is None else np.asarray(classes, np.int64)
    nrm = geo["n"][rows]
    sin_tilt = np.sqrt(nrm[:, 0] * nrm[:, 0] + nrm[:, 1] * nrm[:, 1]).astype(f32)
    hbv = geo["hbv"][rows, cls] if trees else geo["hbv_no_trees"][rows]
    return {"cos_zenith": np.asarray(cos_zenith, f32), "horizon_view": hbv,
            "reflector_horizon": (geo["refl_hor"][rows, cls] if with_reflectors
                                  else np.zeros(len(rows), f32)),
            "sin_tilt": sin_tilt}


def _add_seconds(timings: dict | None, **seconds: float) -> None:
    """Add *seconds* to the caller's *timings* (if any) under their names."""
    if timings is not None:
        for key, s in seconds.items():
            timings[key] = timings.get(key, 0.0) + s


def pass_sample_key(segment_id, t_utc) -> np.ndarray:
    """A well-mixed integer per pass from its segment and time (splitmix64 finaliser), so
    the reflector sample point a pass traces does not depend on batching or workers.

    Parameters
    ----------
    segment_id : (n,) int, segment of each pass
    t_utc : (n,) float, Unix s at the segment start (rounded to the millisecond)

    Returns
    -------
    (n,) int64 in [0, 2**31): reflector ``j`` of the pass traces sample point
    ``(key + j) mod P`` (:func:`roof_irradiance`), and ``key >> 4`` seeds its roulette
    (:func:`_roulette`).  The compiled kernel computes the same key per pass
    (:mod:`vipvflow.models.passkernel`).

    References
    ----------
    S. Vigna, splitmix64 (public domain), the finaliser of ``java.util.SplittableRandom``.
    """
    x = (np.asarray(segment_id, np.int64).astype(np.uint64) * np.uint64(0x9E3779B97F4A7C15)
         + np.round(np.asarray(t_utc, np.float64) * 1000.0).astype(np.int64).astype(np.uint64))
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    x = x ^ (x >> np.uint64(31))
    return (x >> np.uint64(33)).astype(np.int64)


def evaluate_passes(passes: pd.DataFrame, segments: pd.DataFrame, geometry: pd.DataFrame,
                    radiation_table, scene, cfg: IrradianceCfg | None = None,
                    ground_albedo: float = 0.20, time_at: str = "mid",
                    packed: dict | None = None, timings: dict | None = None,
                    kernel: str = "fused") -> pd.DataFrame:
    """Irradiance components on the roof for every pass (W/m2).

    Parameters
    ----------
    passes : DataFrame with ``segment_id`` and ``t_utc`` (Unix s at the segment start);
        with ``dt_s`` and ``time_at='mid'`` the sun and radiation are taken at the middle
        of the time on the segment
    segments : DataFrame of the segments (unused: *geometry* holds all per-segment data;
        kept for the stage contract)
    geometry : DataFrame from :func:`segment_geometry`; an optional ``rad_location`` column
        (int, see :meth:`RadiationTable.nearest_location`) picks the CAMS location per segment
    radiation_table : vipvflow.models.sun_sky.RadiationTable
    scene : vipvflow.models.shading.Scene
    cfg : IrradianceCfg
    ground_albedo : float, albedo of the ground lighting the reflectors (eq. 3)
    time_at : ``'mid'`` or ``'start'``
    packed : dict, optional
        ``pack_geometry(geometry, cfg, ground_albedo, scene)`` when the caller keeps it
        (a worker evaluating the same tile for several months packs it once)
    timings : dict, optional
        Seconds by stage are added to it: ``lookup_s`` radiation and sun lookup,
        ``ray_setup_s`` building the occlusion batch, ``rays_s`` the Embree query,
        ``components_s`` the component arithmetic, ``pack_s`` packing the geometry and
        filling the output (the caller times; the kernel keeps no state); with the fused
        kernel ``ray_setup_s`` includes the radiation lookup
    kernel : ``'fused'`` (default) the compiled kernel of :mod:`vipvflow.models.passkernel` where
        the packed geometry holds the scene's frame, else, and with ``'numpy'``, the numpy
        reference (:func:`roof_irradiance` per chunk); equal to float32 precision

    Returns
    -------
    DataFrame indexed like *passes*: ``direct, diffuse, reflected, total`` and the
    ``_clear`` variants, ``total_unshaded``, ``total_clear_unshaded``, ``direct_no_trees``,
    ``diffuse_no_trees`` (the buildings alone, all-sky), and the horizontal ``ghi``,
    ``ghi_clear`` at the pass (float32, W/m2), ``sun_visible`` (bool).  The crowns' class
    of months is the pass's month (UTC calendar, at the time the radiation is taken).

    References
    ----------
    The paper (section 3: direct, isotropic diffuse and reflected light on the roof); the
    sky view factor of Oke (J. Climatol. 1, 1981) for the default diffuse model; pvlib
    ``irradiance.get_total_irradiance`` for the unshaded plane of array.
    """
    cfg = cfg or IrradianceCfg()
    del segments
    clock = {} if timings is None else timings
    for k in ("lookup_s", "ray_setup_s", "rays_s", "components_s", "pack_s"):
        clock.setdefault(k, 0.0)
    t_pack = time.perf_counter()
    ids = geometry["segment_id"].to_numpy(np.int64)
    pos = np.full(int(ids.max()) + 1 if len(ids) else 1, -1, np.int64)
    pos[ids] = np.arange(len(ids))
    seg = passes["segment_id"].to_numpy(np.int64)
    if len(seg) and (seg.max() >= len(pos) or seg.min() < 0 or (pos[seg] < 0).any()):
        raise KeyError("passes reference segments missing from the geometry")
    row = pos[seg]
    t_start = passes["t_utc"].to_numpy(np.float64)
    t = t_start
    if time_at == "mid" and "dt_s" in passes.columns:
        t = t + 0.5 * passes["dt_s"].to_numpy(np.float64)
    geo = packed if packed is not None else pack_geometry(geometry, cfg, ground_albedo, scene)
    loc_col = geometry["rad_location"].to_numpy(np.int64) if "rad_location" in geometry else None
    n = len(passes)
    columns = list(COMPONENTS) + ["ghi", "ghi_clear"]
    if kernel == "fused":
        from . import passkernel

        if passkernel.usable(geo, scene):
            mid = time_at == "mid" and "dt_s" in passes.columns
            dt = (np.ascontiguousarray(passes["dt_s"].to_numpy(np.float64)) if mid
                  else np.zeros(n))
            clock["pack_s"] += time.perf_counter() - t_pack
            block, visible = passkernel.evaluate_block(
                np.ascontiguousarray(seg), np.ascontiguousarray(t_start), dt, mid,
                np.ascontiguousarray(row), geo, cfg, radiation_table, scene, loc_col, clock)
            df = pd.DataFrame(block, index=passes.index, columns=columns, copy=False)
            df["sun_visible"] = visible
            return df
    elif kernel != "numpy":
        raise ValueError(f"kernel must be 'fused' or 'numpy', not {kernel!r}")
    block = np.zeros((len(columns), n), np.float32).T      # column-major: one block per column
    visible = np.zeros(n, bool)
    # passes at night (every radiation value exactly 0) have every component exactly 0:
    # only the others are looked up and ray-cast
    t_look = time.perf_counter()
    clock["pack_s"] += t_look - t_pack
    active = np.flatnonzero(radiation_table.has_light(
        t, location=None if loc_col is None else loc_col[row]))
    clock["lookup_s"] += time.perf_counter() - t_look
    for a in range(0, len(active), _CHUNK):
        idx = active[a:a + _CHUNK]
        t_look = time.perf_counter()
        r = row[idx]
        loc = None if loc_col is None else loc_col[r]
        rad = radiation_table.lookup(t[idx], location=loc, angles=False)
        month = month_of(t[idx])
        if cfg.diffuse_model == "perez_svf" and geo["sky_x"].shape[1]:
            cls = pass_classes(geo, r, month)
            for sfx in ("", "_clear"):
                rad["sky_share" + sfx], rad["sky_open" + sfx] = radiation_table.sky_share(
                    t[idx], geo["sky_x"][r], geo["n"][r], loc, clear=bool(sfx))
                if geo["tsky"].shape[2]:
                    rad["sky_tree" + sfx] = radiation_table.sky_tree_share(
                        t[idx], geo["tsky"][r, cls], geo["n"][r], loc, clear=bool(sfx))
        sun = np.stack([rad["sun_x"], rad["sun_y"], rad["sun_z"]], 1)
        key = pass_sample_key(seg[idx], t_start[idx])
        clock["lookup_s"] += time.perf_counter() - t_look
        out = roof_irradiance(geo, r, sun, rad, scene, cfg, ground_albedo, sample=key,
                              timings=clock, month=month)
        t_pack = time.perf_counter()
        for j, k in enumerate(COMPONENTS):
            block[idx, j] = out[k]
        block[idx, -2] = np.nan_to_num(rad["ghi"])
        block[idx, -1] = np.nan_to_num(rad["ghi_clear"])
        visible[idx] = out["sun_visible"]
        clock["pack_s"] += time.perf_counter() - t_pack
    df = pd.DataFrame(block, index=passes.index, columns=columns, copy=False)
    df["sun_visible"] = visible
    return df
