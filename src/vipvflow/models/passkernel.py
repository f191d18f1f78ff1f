"""The fused per-pass kernel: pass time -> radiation -> rays -> components -> sums.

The same physics as :func:`vipvflow.models.irradiance.roof_irradiance` (eqs. 1-3 of the paper, the
street reflectors, the rotating reflector sample point and its Russian roulette), compiled
with numba into loops over the passes around the one Embree occlusion query numba cannot
call:

1. :func:`_setup` looks up the radiation and the sun at each pass's time (linear in time,
   the :meth:`vipvflow.models.sun_sky.RadiationTable.lookup` arithmetic), skips dark passes, and
   writes the pass's rays (the roof point towards the sun, unless the segment's sun mask
   among the buildings tells it clear; one per reflector facing it) straight into the
   ray batch;
2. Embree answers the batch (:meth:`vipvflow.models.shading.Scene.occluded_local`);
3. with the Perez sky, :func:`_sky_terms` sums each segment's sky (and what the crowns take
   from it) over the sky steps from its first pass to its last in the chunk
   (:func:`_sky_grid`) and gives each pass its own;
4. :func:`_finish` sums the components per pass into the output block of
   :func:`vipvflow.models.irradiance.evaluate_passes`, or adds their
   irradiation (Wh/m2) straight into the (segment, local hour) and (trip, date) bins of a
   partition (:func:`vipvflow.simulation.partition.aggregate_partition`).

No per-pass array is made beyond the ray batch, the radiation values and sky terms of the
chunk and the pass's place in the batch.  Every float32 operation is the numpy reference's,
in the same order, so the components are equal to float32 precision (the tests check it); the sums are
float64, like the reference's ``bincount``.

The kernels compile once per process on first use and are cached on disk
(``cache=True``: next to this module, or in numba's user cache directory when that is not
writable); :func:`warm` loads them (the Dask worker preload calls it).

References
----------
Paper (Pera et al., see ``CITATION.cff``) sections 3.2.1-3.2.3 (eqs. 1-3) and 3.3 (energy);
pvlib ``irradiance.get_total_irradiance(model='isotropic')``, ``irradiance.aoi``.
S. K. Lam, A. Pitrou, S. Seibert (2015), Numba: a LLVM-based Python JIT compiler, LLVM-HPC
'15.  pvlib uses numba for its solar position algorithm (``pvlib.spa``).
"""
from __future__ import annotations

import time
from functools import lru_cache

import numpy as np
from numba import njit

from .horizon import BUILDING_SECTORS, MASK_FLOOR, building_masks, building_sector
from .irradiance import ROULETTE_WEIGHT
from .sky import COS_85, SECTOR_COS, SECTOR_SIN, SKY_AZIMUTH_BINS, SKY_LEVELS, SKY_PACK
from .trees import _MAX_HITS, MASK_SECTORS, mask_sector, month0, transmit_one

#: components of a pass in the order of the kernel's output block (W/m2)
BLOCK_COLUMNS = ("direct", "diffuse", "reflected", "total", "direct_clear", "diffuse_clear",
                 "reflected_clear", "total_clear", "total_unshaded", "total_clear_unshaded",
                 "direct_no_trees", "diffuse_no_trees", "ghi", "ghi_clear")
_NB = len(BLOCK_COLUMNS)
#: rays in one batch (bounds the batch's memory: 24 bytes a ray, ~60 bytes with the pairs and
#: the passes' rows).  2^18 rather than 2^21: a worker's tile task of the line-year held
#: 47 MB at its peak instead of 101 (tracemalloc), and the batches, a few MB each, stay in
#: the caches between the setup, Embree and the finishing loops (ten of the line-year's tiles
#: over the year 17.5 and 16.7 s against 19.0 and 18.7; the 200-line network's busiest tile
#: in June 16.1 against 17.2 s, the mean of four each; alternated in one process)
RAY_BUDGET = 1 << 18
#: radiation columns the kernel reads, in this order (then the Perez sky's coefficients)
_RAD = ("dni", "dhi", "ghi", "dni_clear", "dhi_clear", "ghi_clear", "sun_x", "sun_y", "sun_z",
        "f1", "f2", "f1_clear", "f2_clear")
_N_RAD = len(_RAD)
#: per pass after the radiation: the Perez sky tables' row nearest in time, the crowns'
#: class of the pass's month
_N_ROW = _N_RAD + 2
_CLS = _N_RAD + 1
_COS_85 = np.float32(COS_85)
_SEC_SIN = SECTOR_SIN.astype(np.float32)
_SEC_COS = SECTOR_COS.astype(np.float32)

_M30, _M27, _M31 = np.uint64(30), np.uint64(27), np.uint64(31)
_C1, _C2, _C3 = np.uint64(0x9E3779B97F4A7C15), np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB)


@njit(cache=True, nogil=True)
def _sample_key(segment_id, t_utc):
    """:func:`vipvflow.models.irradiance.pass_sample_key` of one pass (splitmix64 finaliser)."""
    x = np.uint64(segment_id) * _C1 + np.uint64(np.int64(np.rint(t_utc * 1000.0)))
    x = (x ^ (x >> _M30)) * _C2
    x = (x ^ (x >> _M27)) * _C3
    x = x ^ (x >> _M31)
    return np.int64(x >> np.uint64(33))


@njit(cache=True, nogil=True, inline="always")
def _clear_of_buildings(bmask, r, sx, sy, sz):
    """Whether segment row *r*'s sun mask among the buildings *bmask*
    (:meth:`vipvflow.models.shading.Scene.sun_masks`; no rows: no masks) tells the sun ray
    (*s*) clear: its slope above the mask in its sector."""
    if bmask.shape[0] == 0:
        return False
    h = np.sqrt(np.float64(sx) * sx + np.float64(sy) * sy)
    if not h > 0.0:
        return False
    k = building_sector(np.float64(sx), np.float64(sy), BUILDING_SECTORS)
    return np.float64(sz) / h > bmask[r, k]


@njit(cache=True, nogil=True)
def _setup(lo, hi, seg, t_start, dt, mid, row, loc_of_row, packed, cols, t0, step,
           nrm, wn, tree_month, p_local, gp_local, rotate, roulette_w, perez, sky_rows, sky_t0,
           sky_step, bmask, rad, cos_aoi, pass_ray, pair_w, pair_pass, pair_pt, o, d, done, free):
    """Radiation lookup and ray batch of passes ``lo..hi`` (see the module docstring).

    Fills, per pass ``i`` (chunk index ``i - lo``): ``rad`` (:data:`_RAD`, NaN as 0, sun
    components as looked up; the Perez coefficients 0 unless *perez*), ``cos_aoi``,
    ``pass_ray`` (the pass's first ray in the batch;
    ``pass_ray[i + 1] - pass_ray[i]`` rays: its direct ray first when the sun is in front of
    the roof and the segment's sun mask among the buildings *bmask* cannot tell it clear
    (``free[i]`` True where it can: no ray), then per reflector pair one ray, or P with
    ``rotate`` False), ``done[i]`` False for a dark pass (every component 0).
    ``pair_w`` / ``pair_pass``: per pair its beam weight and pass (chunk index),
    ``pair_pt`` its (first) sample point's flat index (reflector x P + point).
    ``rad[c, _CLS]``: the crowns' class of the pass's month (*tree_month*, per geometry
    row; *wn* per row and class).  Returns (rays, pairs).
    """
    n_t = packed.shape[1]
    J = wn.shape[2]
    P = gp_local.shape[1]
    nr = 0
    npair = 0
    last_day, month = np.nan, np.int64(0)
    for i in range(lo, hi):
        c = i - lo
        pass_ray[c] = nr
        cos_aoi[c] = np.float32(0.0)
        done[c] = False
        free[c] = False
        t = t_start[i] + 0.5 * dt[i] if mid else t_start[i]
        f = (t - t0) / step
        if not (f >= 0.0 and f <= n_t - 1):
            continue              # outside the radiation grid (or NaN): every value 0
        ii = min(np.int64(f), n_t - 2) if n_t > 1 else np.int64(0)
        w = np.float32(f - ii)
        r = row[i]
        li = loc_of_row[r]
        dark = True
        for q in range(_N_RAD):
            if q >= 9 and not perez:
                rad[c, q] = np.float32(0.0)
                continue
            a = packed[li, ii, cols[q]]
            b = packed[li, ii + 1, cols[q]] if n_t > 1 else a
            v = a + w * (b - a)
            if q < 6 or q >= 9:
                if np.isnan(v):
                    v = np.float32(0.0)
                if q < 6 and v != 0:
                    dark = False
            rad[c, q] = v
        if dark:
            continue
        done[c] = True
        day = np.floor(t / 86400.0)
        if day != last_day:      # the month of the day before (passes come in days)
            last_day, month = day, month0(t)
        cls = tree_month[r, month]
        rad[c, _CLS] = np.float32(cls)
        if sky_rows.shape[1]:
            # the Perez sky tables' row nearest the pass (RadiationTable.sky_steps)
            js = np.int64(min(max(np.floor((t - sky_t0) / sky_step + 0.5), 0.0),
                              sky_rows.shape[1] - 1))
            rad[c, _N_RAD] = np.float32(sky_rows[li, js])
        sx, sy, sz = rad[c, 6], rad[c, 7], rad[c, 8]
        # the circumsolar part of the Perez sky travels the sun ray, like the beam
        if not (sz > 0 and (rad[c, 0] > 0 or rad[c, 3] > 0 or rad[c, 9] > 0 or rad[c, 11] > 0)):
            continue
        ca = nrm[r, 0] * sx + nrm[r, 1] * sy + nrm[r, 2] * sz
        ca = max(ca, np.float32(0.0))
        cos_aoi[c] = ca
        if ca > 0:
            if _clear_of_buildings(bmask, r, sx, sy, sz):
                free[c] = True
            else:
                o[nr, 0], o[nr, 1], o[nr, 2] = p_local[r, 0], p_local[r, 1], p_local[r, 2]
                d[nr, 0], d[nr, 1], d[nr, 2] = sx, sy, sz
                nr += 1
        if J == 0:
            continue
        key = _sample_key(seg[i], t_start[i]) if rotate else np.int64(0)
        for g in range(J):
            wc = wn[r, cls, g, 0] * sx + wn[r, cls, g, 1] * sy + wn[r, cls, g, 2] * sz
            if not wc > 0:
                continue
            beam = wc
            if rotate and wc < roulette_w:
                k = (key >> 4) * 0x2545F491 + np.int64(g) * 0x9E3779B1
                u = np.float32((k ^ (k >> 29)) & 0xFFFFFF) * np.float32(1.0 / (1 << 24))
                if not u * roulette_w < wc:
                    continue
                beam = max(wc, roulette_w)
            pair_w[npair] = beam
            pair_pass[npair] = c
            base = (r * J + g)
            pair_pt[npair] = base * P
            npair += 1
            if rotate:
                k = (key + g) % P
                pair_pt[npair - 1] = base * P + k
                for j in range(3):
                    o[nr, j] = gp_local[base, k, j]
                d[nr, 0], d[nr, 1], d[nr, 2] = sx, sy, sz
                nr += 1
            else:
                for k in range(P):
                    for j in range(3):
                        o[nr, j] = gp_local[base, k, j]
                    d[nr, 0], d[nr, 1], d[nr, 2] = sx, sy, sz
                    nr += 1
    pass_ray[hi - lo] = nr
    return nr, npair


#: float32 values of the sky grids :func:`_sky_terms` holds at once (32 MB)
SKY_GRID_BUDGET = 8 << 20


@njit(cache=True, nogil=True)
def _level_differences(TT, s0, m, ts, segs, n_used, DT):
    """Into ``DT[b]`` the packed sky tables' difference between a cell and the cell one
    level up (``TT[b] - TT[b + SKY_PACK]``, float32) at steps ``s0 .. s0 + m``, for the rows
    *b* of the cells the crowns of the segments *segs* take sky from (:func:`_sky_grid`):
    each made once a chunk rather than once per segment and crown cell; the same float32
    values, so the sums are unchanged bit for bit."""
    off, cell = ts[0], ts[1]
    made = np.zeros(DT.shape[0] // SKY_PACK, np.bool_)
    for q in range(n_used):
        r = segs[q]
        for e in range(off[r], off[r + 1]):
            k = cell[e]
            if made[k]:
                continue
            made[k] = True
            b = SKY_PACK * k
            for u in range(SKY_PACK):
                lo_row, hi_row, out = TT[b + u, s0:s0 + m], TT[b + SKY_PACK + u, s0:s0 + m], DT[b + u]
                for i in range(m):
                    out[i] = lo_row[i] - hi_row[i]


@njit(cache=True, nogil=True)
def _sky_grid(TT, s0, d0, m, r, sky_cell, sky_f, sky_t, sky_tilted, nrm, ts, cls_used, DT, g):
    """Segment row *r*'s Perez sky at sky steps ``s0 .. s0 + m`` (*TT*: the packed tables,
    :func:`vipvflow.models.sky.pack_sky`) into ``g[:, :m]`` (*g*: (2 + 2 C, >= m) float32):
    row 0 its share of DHI all-sky, row 1 clear-sky (per sector its cell, interpolation
    weight and tilt weight, summed in sector order: :func:`vipvflow.models.sky.sky_share`),
    rows ``2 + 2 c`` and ``3 + 2 c`` what the crowns of class *c* take from it (its sky
    cells with a loss, ``sum loss (n_z dG + t_k dH)`` cell by cell:
    :func:`vipvflow.models.sky.tree_share`),
    for the classes in *cls_used* (*DT*: the tables' level differences ``TT[b] - TT[b + 4]``
    from the step ``s0 - d0`` on, :func:`_level_differences`).  Each step's sum is the
    per-pass sum, term by term in the same order; the steps side by side make every loop a
    run over contiguous memory."""
    for q in range(g.shape[0]):
        for i in range(m):
            g[q, i] = np.float32(0.0)
    nz = nrm[r, 2]
    a, c = g[0], g[1]
    e1 = s0 + m
    for k in range(sky_cell.shape[1]):
        b = SKY_PACK * sky_cell[r, k]
        f, t = sky_f[r, k], sky_t[r, k]
        ga0, ga1 = TT[b, s0:e1], TT[b + SKY_PACK, s0:e1]
        gc0, gc1 = TT[b + 2, s0:e1], TT[b + SKY_PACK + 2, s0:e1]
        if sky_tilted[r]:
            ha0, ha1 = TT[b + 1, s0:e1], TT[b + SKY_PACK + 1, s0:e1]
            hc0, hc1 = TT[b + 3, s0:e1], TT[b + SKY_PACK + 3, s0:e1]
            for i in range(m):
                a[i] += nz * (ga0[i] + f * (ga1[i] - ga0[i])) + t * (ha0[i] + f * (ha1[i] - ha0[i]))
                c[i] += nz * (gc0[i] + f * (gc1[i] - gc0[i])) + t * (hc0[i] + f * (hc1[i] - hc0[i]))
        else:
            for i in range(m):
                a[i] += nz * (ga0[i] + f * (ga1[i] - ga0[i]))
                c[i] += nz * (gc0[i] + f * (gc1[i] - gc0[i]))
    off, cell, sector, w = ts
    d1 = d0 + m
    for q in range(cls_used.shape[0]):
        if not cls_used[q]:
            continue
        la, lc = g[2 + 2 * q], g[3 + 2 * q]
        for e in range(off[r], off[r + 1]):
            b = SKY_PACK * cell[e]
            tk, we = sky_t[r, sector[e]], w[e, q]
            dga, dha, dgc, dhc = DT[b, d0:d1], DT[b + 1, d0:d1], DT[b + 2, d0:d1], DT[b + 3, d0:d1]
            for i in range(m):
                la[i] += we * (nz * dga[i] + tk * dha[i])
                lc[i] += we * (nz * dgc[i] + tk * dhc[i])


@njit(cache=True, nogil=True, inline="always")
def _components(c, r, rad, cos_aoi, vis_t, visible, beam_sum, sky, sky_nt, iso, refl_sky,
                refl_ghi, perez, hbv, hbv_nt, refl_hor, sin_tilt, has_sky, terms, out):
    """The :data:`BLOCK_COLUMNS` of one pass into *out* (float32, as
    :func:`vipvflow.models.irradiance.roof_components` sums them, the Perez sky with
    *perez*; with *has_sky* the sky the roof point sees from :func:`_sky_terms`' *terms*):
    the sun ray's transmittance *vis_t* (0, or the crowns' where the buildings let it
    through: *visible*), the sky through the crowns of the pass's class; the ``_no_trees``
    columns with the buildings alone."""
    ca = cos_aoi[c]
    cls = np.int64(rad[c, _CLS])
    vis_b = np.float32(1.0) if visible else np.float32(0.0)
    for s in range(2):
        b, dh, gh = rad[c, 3 * s], rad[c, 3 * s + 1], rad[c, 3 * s + 2]
        beam = b * ca
        direct = beam * vis_t
        direct_nt = beam * vis_b
        if perez:
            f1, f2 = rad[c, 9 + 2 * s], rad[c, 10 + 2 * s]
            cs = dh * f1 / max(rad[c, 8], _COS_85)
            circ = cs * ca
            iso_w = np.float32(1.0) - f1
            if has_sky:
                share, share_open, loss = terms[c, s], terms[c, 2 + s], terms[c, 4 + s]
                diffuse = max(dh * (share - loss), np.float32(0.0))
                diffuse_nt = max(dh * share, np.float32(0.0))
            else:
                diffuse = max(dh * (iso_w * sky[r, cls] + f2 * hbv[r, cls]) + circ * vis_t,
                              np.float32(0.0))
                diffuse_nt = max(dh * (iso_w * sky_nt[r] + f2 * hbv_nt[r]) + circ * vis_b,
                                 np.float32(0.0))
            reflected = ((b + cs) * beam_sum + dh * (iso_w * refl_sky[r, cls] + f2 * refl_hor[r, cls])
                         + gh * refl_ghi[r, cls])
            if has_sky:
                unshaded = beam + max(dh * share_open, np.float32(0.0))
            else:
                unshaded = beam + max(dh * (iso_w * iso[r] + f2 * sin_tilt[r]) + circ, np.float32(0.0))
        else:
            diffuse = dh * sky[r, cls]
            diffuse_nt = dh * sky_nt[r]
            reflected = b * beam_sum + dh * refl_sky[r, cls] + gh * refl_ghi[r, cls]
            unshaded = beam + dh * iso[r]
        out[4 * s] = direct
        out[4 * s + 1] = diffuse
        out[4 * s + 2] = reflected
        out[4 * s + 3] = direct + diffuse + reflected
        out[8 + s] = unshaded
        if s == 0:
            out[10] = direct_nt
            out[11] = diffuse_nt
    out[12] = rad[c, 2]
    out[13] = rad[c, 5]


@njit(cache=True, nogil=True)
def _sky_terms(lo, hi, row, rad, done, sky_cell, sky_f, sky_t, sky_tilted, TT, to_all, to_clear, nrm,
               ts, budget, terms):
    """The Perez sky a pass's roof point sees, for passes ``lo..hi`` (chunk index
    ``i - lo``), into *terms* (chunk, 6) float32: its share of DHI all-sky and clear-sky,
    the same in the open, and the crowns' loss from it in the pass's class of months; 0 for
    a dark pass or where the sun is more than 3 deg down (the tables' row -1).

    A segment's sky depends on the pass only through the sky step (15 min) and the class:
    the sums are made per segment over every step from its first pass's to its last's in
    the chunk (:func:`_sky_grid`, at most *budget* float32 values at a time, in blocks of
    segments) and each pass reads its own.  Equal to the per-pass sums bit for bit; ~5x
    faster than them (the steps' sums run side by side in vector registers).  On a network a
    chunk's steps cover about one day's daylight, as do its segments' own (the 200-line
    network's busiest tile in June, :data:`RAY_BUDGET` 2^18: 248 chunks of 43,690 passes,
    64-66 steps each from the 10th to the 90th percentile, each segment's 61 at the median;
    19.7 M sums, 20.4 M with chunks 8 times as long)."""
    n_seg = sky_cell.shape[0]
    C = ts[3].shape[1] if ts[1].shape[0] else 0         # classes of months, where crowns take sky
    s_lo, s_hi = np.int64(1) << 62, np.int64(-1)
    slot = np.full(n_seg, -1, np.int64)
    first = np.empty(n_seg, np.int64)                   # a used segment's first and last step
    last = np.empty(n_seg, np.int64)
    cls_used = np.zeros(max(C, 1), np.bool_)
    n_used = 0
    for i in range(lo, hi):
        c = i - lo
        for k in range(6):
            terms[c, k] = np.float32(0.0)
        if not done[c]:
            continue
        rs = np.int64(rad[c, _N_RAD])
        if rs < 0:
            continue
        r = row[i]
        nx, ny, nz = nrm[r, 0], nrm[r, 1], nrm[r, 2]
        terms[c, 2] = nz + (nx * to_all[rs, 0] + ny * to_all[rs, 1])
        terms[c, 3] = nz + (nx * to_clear[rs, 0] + ny * to_clear[rs, 1])
        s_lo, s_hi = min(s_lo, rs), max(s_hi, rs)
        if C:
            cls_used[np.int64(rad[c, _CLS])] = True
        if slot[r] < 0:
            slot[r] = n_used
            n_used += 1
            first[r], last[r] = rs, rs
        else:
            first[r], last[r] = min(first[r], rs), max(last[r], rs)
    if n_used == 0:
        return
    segs = np.empty(n_used, np.int64)
    for r in range(n_seg):
        if slot[r] >= 0:
            segs[slot[r]] = r
    m = s_hi - s_lo + 1
    rows = 2 + 2 * C
    per_block = max(np.int64(1), budget // (rows * m))
    g = np.empty((min(per_block, n_used), rows, m), np.float32)
    DT = np.empty((TT.shape[0] if C else 0, m), np.float32)
    if C:
        _level_differences(TT, s_lo, m, ts, segs, n_used, DT)
    for b0 in range(0, n_used, per_block):
        b1 = min(n_used, b0 + per_block)
        for q in range(b0, b1):
            r = segs[q]
            _sky_grid(TT, first[r], first[r] - s_lo, last[r] - first[r] + 1, r, sky_cell, sky_f,
                      sky_t, sky_tilted, nrm, ts, cls_used, DT, g[q - b0])
        for i in range(lo, hi):
            c = i - lo
            if not done[c]:
                continue
            rs = np.int64(rad[c, _N_RAD])
            q = slot[row[i]]
            if rs < 0 or q < b0 or q >= b1:
                continue
            j = rs - first[row[i]]
            terms[c, 0] = g[q - b0, 0, j]
            terms[c, 1] = g[q - b0, 1, j]
            if C:
                cls = np.int64(rad[c, _CLS])
                terms[c, 4] = g[q - b0, 2 + 2 * cls, j]
                terms[c, 5] = g[q - b0, 3 + 2 * cls, j]


@njit(cache=True, nogil=True, inline="always")
def _may_cross(smask, r, dx, dy, dz):
    """Whether the sun ray (direction *d*) from segment row *r*'s roof point may cross a
    crown: its slope not above the row's mask in its sector
    (:func:`vipvflow.models.trees.sun_masks`)."""
    h = np.sqrt(np.float64(dx) * dx + np.float64(dy) * dy)
    if not h > 0.0:
        return True
    return not np.float64(dz) / h > smask[r, mask_sector(np.float64(dx), np.float64(dy))]


@njit(cache=True, nogil=True)
def _visibility(lo, hi, row, pass_ray, pair_w, pair_pt, gf, occ, done, cos_aoi, free, rad,
                p_local, rotate, P, o, d, tmax, tr, smask, visible, vis_t, beam_sum):
    """Per pass ``lo..hi`` (chunk index): whether its sun ray misses the buildings
    (*visible*), its transmittance (*vis_t*: 0, else the crowns' along it in the pass's
    class; 1 without a walk where segment row's sun mask *smask* rules the crowns out) and
    its reflectors' beam sum ``sum weight x lit`` (*beam_sum*: float64 like the reference's
    bincount, then float32; a sample point's ray lit in the crowns' transmittance, times
    the point's factor through the crowns *gf*).  A pass whose sun mask among the buildings
    told its sun ray clear (*free*) has no ray of its own: it starts at the roof point
    (*p_local*) towards the sun (*rad*).

    One loop over the chunk with the crowns' arrays (*tr*) taken apart once, before the
    loop: the same loop calling an inlined per-pass helper that took them apart per pass
    was ~4x slower (149 against 39 ns a pass on L1's June chunks)."""
    cx, cy, cz, ia2, ic2, meta, start, items, tau = tr
    trees = items.shape[0] > 0
    hits = np.empty(_MAX_HITS, np.int64)
    q = 0
    for i in range(lo, hi):
        c = i - lo
        visible[c] = False
        vis_t[c] = np.float32(0.0)
        beam_sum[c] = np.float32(0.0)
        if not done[c]:
            continue
        cls = np.int64(rad[c, _CLS])
        r = row[i]
        r0, r1 = pass_ray[c], pass_ray[c + 1]
        if cos_aoi[c] > 0:
            if free[c]:
                seen = True
                ox, oy, oz = p_local[r, 0], p_local[r, 1], p_local[r, 2]
                dx, dy, dz = rad[c, 6], rad[c, 7], rad[c, 8]
            else:
                seen = not occ[r0]
                ox, oy, oz = o[r0, 0], o[r0, 1], o[r0, 2]
                dx, dy, dz = d[r0, 0], d[r0, 1], d[r0, 2]
                r0 += 1
            if seen:
                visible[c] = True
                t_sun = np.float32(1.0)
                # the crowns' walk only where the segment's sun mask cannot rule them out
                if trees and _may_cross(smask, r, dx, dy, dz):
                    t_sun = transmit_one(ox, oy, oz, dx, dy, dz, tmax, cls, cx, cy, cz, ia2,
                                         ic2, meta, start, items, tau, hits)
                vis_t[c] = t_sun
        acc = 0.0
        while r0 < r1:
            if rotate:
                t = np.float32(0.0)
                if not occ[r0]:
                    t = np.float32(1.0)
                    if trees:
                        t = transmit_one(o[r0, 0], o[r0, 1], o[r0, 2], d[r0, 0], d[r0, 1],
                                         d[r0, 2], tmax, cls, cx, cy, cz, ia2, ic2, meta, start,
                                         items, tau, hits)
                t = t * gf[pair_pt[q], cls]
                acc += np.float64(pair_w[q] * t)
                r0 += 1
            else:
                tsum = 0.0
                for k in range(P):
                    if not occ[r0 + k]:
                        t = np.float32(1.0)
                        if trees:
                            j = r0 + k
                            t = transmit_one(o[j, 0], o[j, 1], o[j, 2], d[j, 0], d[j, 1],
                                             d[j, 2], tmax, cls, cx, cy, cz, ia2, ic2, meta,
                                             start, items, tau, hits)
                        tsum += np.float64(t * gf[pair_pt[q] + k, cls])
                share = tsum * np.float64(np.float32(1.0 / P))
                acc += np.float64(pair_w[q]) * share
                r0 += P
            q += 1
        beam_sum[c] = np.float32(acc)


@njit(cache=True, nogil=True)
def _finish(lo, hi, row, rad, cos_aoi, pass_ray, pair_w, pair_pass, pair_pt, gf, occ, done,
            free, p_local, sky, sky_nt, iso, refl_sky, refl_ghi, perez, hbv, hbv_nt, refl_hor,
            sin_tilt, has_sky, terms, rotate, P, o, d, tmax, tr, smask, to_bins, block,
            visible_out, dt, seg_hour, run, seg_bins, run_bins):
    """Components of passes ``lo..hi``: into columns of *block* (14, n) and *visible_out*,
    or, with *to_bins*, as irradiation (Wh/m2) added into ``seg_bins[seg_hour[i]]`` and
    ``run_bins[run[i]]`` ((bins, 14) float64, :data:`BLOCK_COLUMNS`); the other side's
    arrays are not touched (empty ones will do).  *o*, *d*: the chunk's rays (the crowns
    along those the buildings let through, *tr*: :meth:`vipvflow.models.trees.Crowns.arrays`).
    The rays' answers first (:func:`_visibility`), then the arithmetic in a loop of its own."""
    m = hi - lo
    visible = np.empty(m, np.bool_)
    vis_t = np.empty(m, np.float32)
    beam_sum = np.empty(m, np.float32)
    _visibility(lo, hi, row, pass_ray, pair_w, pair_pt, gf, occ, done, cos_aoi, free, rad,
                p_local, rotate, P, o, d, tmax, tr, smask, visible, vis_t, beam_sum)
    out = np.empty(_NB, np.float32)
    for i in range(lo, hi):
        c = i - lo
        if not done[c]:
            continue
        _components(c, row[i], rad, cos_aoi, vis_t[c], visible[c], beam_sum[c], sky, sky_nt,
                    iso, refl_sky, refl_ghi, perez, hbv, hbv_nt, refl_hor, sin_tilt, has_sky,
                    terms, out)
        if to_bins:
            w = dt[i] / 3600.0
            b, k = seg_hour[i], run[i]
            for j in range(_NB):
                h = np.float64(out[j]) * w
                seg_bins[b, j] += h
                run_bins[k, j] += h
        else:
            for j in range(_NB):
                block[j, i] = out[j]
            visible_out[i] = visible[c]


#: empty stand-ins for the side of :func:`_finish` a call does not fill
_NO_INT = np.zeros(0, np.int64)
_NO_BINS = np.zeros((0, _NB))
_NO_BLOCK = np.zeros((_NB, 0), np.float32)
_NO_VISIBLE = np.zeros(0, np.bool_)


@njit(cache=True, nogil=True)
def _groups(trip_code, day, seg, t_utc, dt, seg_lo, seg_pos_of, hour_lo, offset_s,
            run, seg_pos, seg_hour, hour):
    """Each pass's run (a new one where trip or service day changes), segment position,
    local clock hour (UTC offset per UTC hour from *hour_lo*) and (segment, hour) bin;
    returns the number of runs."""
    n_runs = 0
    for i in range(len(seg)):
        if i == 0 or trip_code[i] != trip_code[i - 1] or day[i] != day[i - 1]:
            n_runs += 1
        run[i] = n_runs - 1
        p = seg_pos_of[seg[i] - seg_lo]
        seg_pos[i] = p
        t = t_utc[i]
        h = np.int64(np.floor((t + offset_s[np.int64(np.floor(t / 3600.0)) - hour_lo]) / 3600.0)) % 24
        hour[i] = h
        seg_hour[i] = p * 24 + h
    return n_runs


@njit(cache=True, nogil=True)
def _seconds(run, seg_pos, hour, dt, by_run, by_seg, by_hour, n_by_seg, n_by_hour):
    """Time (s) per run, segment and hour, and passes per segment and hour, in pass order."""
    for i in range(len(run)):
        by_run[run[i]] += dt[i]
        by_seg[seg_pos[i]] += dt[i]
        by_hour[hour[i]] += dt[i]
        n_by_seg[seg_pos[i]] += 1
        n_by_hour[hour[i]] += 1


#: UTC hours of one table of :func:`_offset_table` (a leap year and a few days either side)
_OFFSET_TABLE_HOURS = 9000


def utc_offsets(timezone: str, h_lo: int, h_hi: int) -> np.ndarray:
    """The UTC offset (s, float64) of the local clock of *timezone* in each UTC hour
    *h_lo*..*h_hi* (hours since 1970; clock changes fall on UTC hour starts).

    Sliced from a table of ~a year computed once per process and time zone (pandas' time
    zone conversion of a month's hours cost ~1.5 ms, in every partition)."""
    block = h_lo // (_OFFSET_TABLE_HOURS // 2)
    start = block * (_OFFSET_TABLE_HOURS // 2)
    if h_hi - start >= _OFFSET_TABLE_HOURS:
        return _offsets(timezone, h_lo, h_hi)
    return _offset_table(timezone, start)[h_lo - start:h_hi - start + 1]


@lru_cache(maxsize=8)
def _offset_table(timezone: str, start: int) -> np.ndarray:
    table = _offsets(timezone, start, start + _OFFSET_TABLE_HOURS - 1)
    table.flags.writeable = False
    return table


def _offsets(timezone: str, h_lo: int, h_hi: int) -> np.ndarray:
    import pandas as pd

    span = pd.DatetimeIndex(pd.to_datetime(np.arange(h_lo, h_hi + 1) * 3600, unit="s", utc=True))
    local = span.tz_convert(timezone).tz_localize(None)
    return ((local - span.tz_localize(None)) / pd.Timedelta(seconds=1)).to_numpy(np.float64)


def pass_groups(trip_code, day, seg, t_utc, dt, timezone: str, seg_ids=None,
                totals: dict | None = None) -> dict:
    """The (trip, date) run, segment and local hour of every pass, in one compiled loop.

    Parameters
    ----------
    trip_code : (n,) int64, trip of each pass (codes)
    day : (n,) int64, service date (days since 1970)
    seg : (n,) int64, segment id
    t_utc : (n,) float64, Unix s
    dt : (n,) float64, s on the segment
    timezone : str, IANA name of the local clock
    seg_ids : (m,) int64, optional, sorted distinct segment ids holding every id of *seg*
        (the positions index them; default: the distinct ids of *seg*)
    totals : dict, optional, the ``seg_s, seg_n, hour_s, hour_n`` of earlier passes (with
        *seg_ids*), which these passes' are added to, pass after pass: a partition's passes
        in chunks give the sums of all at once, bit for bit

    Returns
    -------
    dict of arrays: ``run``, ``seg_pos`` (position among the sorted distinct ``seg_ids``),
    ``seg_hour`` (``seg_pos x 24 +`` the local hour 0..23), ``starts`` (first pass
    of each run), ``seg_ids``; and per run, segment and hour the seconds ``run_s, seg_s,
    hour_s`` and the pass counts ``seg_n, hour_n`` (*totals*' arrays when given).
    """
    trip_code, day, seg, t_utc, dt = (_writable(a) for a in (trip_code, day, seg, t_utc, dt))
    n = len(seg)
    if seg_ids is not None:
        seg_ids = np.asarray(seg_ids, np.int64)
        lo, hi = (int(seg_ids[0]), int(seg_ids[-1])) if len(seg_ids) else (0, 0)
    else:
        lo, hi = (int(seg.min()), int(seg.max())) if n else (0, 0)
    if hi - lo > 8 * max(n, len(seg_ids) if seg_ids is not None else 0) + 1024:
        # sparse ids: positions by sorting
        if seg_ids is None:
            seg_ids, seg = np.unique(seg, return_inverse=True)
        else:
            seg = np.searchsorted(seg_ids, seg)
        seg, lo, seg_pos_of = _writable(seg.astype(np.int64)), 0, np.arange(len(seg_ids))
    elif seg_ids is None:
        present = np.zeros(hi - lo + 1, bool)
        present[seg - lo] = True
        seg_pos_of = np.cumsum(present) - 1
        seg_ids = np.flatnonzero(present) + lo if n else seg[:0]
    else:
        seg_pos_of = np.full(hi - lo + 1, -1, np.int64)
        seg_pos_of[seg_ids - lo] = np.arange(len(seg_ids))
    h_lo = int(np.floor(t_utc.min() / 3600.0)) if n else 0
    h_hi = int(np.floor(t_utc.max() / 3600.0)) if n else 0
    offset = utc_offsets(timezone, h_lo, h_hi)
    out = {k: np.empty(n, np.int64) for k in ("run", "seg_pos", "seg_hour")}
    hour = np.empty(n, np.int64)            # in seg_hour: not held on (8 bytes a pass)
    n_runs = _groups(trip_code, day, seg, t_utc, dt, lo, seg_pos_of, h_lo, _writable(offset),
                     out["run"], out["seg_pos"], out["seg_hour"], hour)
    new_run = np.empty(n, bool)
    if n:
        new_run[0] = True
        np.not_equal(out["run"][1:], out["run"][:-1], out=new_run[1:])
    if totals is None:
        totals = dict(seg_s=np.zeros(len(seg_ids)), hour_s=np.zeros(24),
                      seg_n=np.zeros(len(seg_ids), np.int64), hour_n=np.zeros(24, np.int64))
    out.update(starts=np.flatnonzero(new_run), seg_ids=seg_ids, run_s=np.zeros(n_runs), **totals)
    _seconds(out["run"], out["seg_pos"], hour, dt, out["run_s"], out["seg_s"],
             out["hour_s"], out["seg_n"], out["hour_n"])
    return out


class _Batch:
    """The work arrays of the kernel, sized for one chunk of passes (uninitialised: the
    setup loop writes every element the finishing loop reads)."""

    def __init__(self, chunk: int, rays_per_pass: int, pairs_per_pass: int):
        f32 = np.float32
        self.rad = np.empty((chunk, _N_ROW), f32)
        self.terms = np.empty((chunk, 6), f32)
        self.cos_aoi = np.empty(chunk, f32)
        self.pass_ray = np.empty(chunk + 1, np.int64)
        self.done = np.empty(chunk, np.bool_)
        self.free = np.empty(chunk, np.bool_)
        self.pair_w = np.empty(chunk * pairs_per_pass, f32)
        self.pair_pass = np.empty(chunk * pairs_per_pass, np.int64)
        self.pair_pt = np.empty(chunk * pairs_per_pass, np.int64)
        self.o = np.empty((chunk * rays_per_pass, 3), f32)
        self.d = np.empty((chunk * rays_per_pass, 3), f32)


def _plan(geo: dict, cfg):
    """Reflectors J, sample points P, rotate, rays and pairs per pass at most, chunk size."""
    J = geo["wn"].shape[2] if (cfg.reflection and cfg.max_reflector_groups) else 0
    P = geo["group_p_local"].shape[1]
    rotate = cfg.reflector_sampling == "rotate" and P > 1
    per_pass = 1 + J * (1 if rotate else P)
    chunk = max(1024, RAY_BUDGET // per_pass)
    return J, P, rotate, per_pass, chunk


def usable(geo: dict, scene) -> bool:
    """Whether the fused kernel can run: origins packed in *scene*'s float32 frame."""
    from .irradiance import _local_frame

    return "group_p_local" in geo and _local_frame(geo, scene)


def _writable(a: np.ndarray) -> np.ndarray:
    """*a* C-contiguous and writable (a copy only where it is not): numba compiles one
    version per array flavour, and :func:`warm` loads the writable one."""
    a = np.ascontiguousarray(a)
    return a if a.flags.writeable else a.copy()


def _inputs(geo: dict, cfg, radiation_table, rows_of_segment_loc, times, scene=None, clock=None):
    f32 = np.float32
    names, packed = radiation_table._packed()
    cols = np.array([names.index(c) for c in _RAD], np.int64)
    n_seg = len(geo["n"])
    nrm = geo["n"]
    C = geo["svf"].shape[1]
    iso = ((f32(1) + nrm[:, 2]) * f32(0.5)).astype(f32)
    if cfg.diffuse_model != "isotropic":
        sky, sky_nt = geo["svf"], geo["svf_no_trees"]
    else:
        sky, sky_nt = np.repeat(iso[:, None], C, axis=1), iso
    J = geo["wn"].shape[2] if (cfg.reflection and cfg.max_reflector_groups) else 0
    zero = np.zeros((n_seg, C), f32)
    r_sky, r_ghi = (geo["refl_sky"], geo["refl_ghi"]) if J else (zero, zero)
    sin_tilt = np.sqrt(nrm[:, 0] * nrm[:, 0] + nrm[:, 1] * nrm[:, 1]).astype(f32)
    hbv, hbv_nt = geo["hbv"], geo["hbv_no_trees"]
    r_hor = geo["refl_hor"] if J else zero
    wn = geo["wn"] if J else np.zeros((n_seg, C, 0, 3), f32)
    loc = (np.zeros(n_seg, np.int64) if rows_of_segment_loc is None
           else np.asarray(rows_of_segment_loc, np.int64))
    x = dict(packed=packed, cols=cols, nrm=nrm, wn=wn.astype(f32, copy=False), p_local=geo["p_local"],
             gp_local=geo["group_p_local"].astype(f32, copy=False), sky=sky.astype(f32, copy=False),
             sky_nt=sky_nt.astype(f32, copy=False), iso=iso, refl_sky=r_sky.astype(f32, copy=False),
             refl_ghi=r_ghi.astype(f32, copy=False), hbv=hbv.astype(f32, copy=False),
             hbv_nt=hbv_nt.astype(f32, copy=False), refl_hor=r_hor.astype(f32, copy=False),
             sin_tilt=sin_tilt, loc=loc, tree_month=geo["tree_month"],
             gf=geo["group_f"].reshape(-1, C))
    x = {k: _writable(v) for k, v in x.items()}
    perez = cfg.diffuse_model == "perez_svf"
    x.update(t0=float(radiation_table.t0), step=float(radiation_table.step_s), perez=perez,
             tmax=float(cfg.ray_length_m))
    crowns = scene.crowns(cfg) if (scene is not None and hasattr(scene, "crowns")) else None
    x["tr"] = tuple(_writable(a) for a in crowns.arrays()) if crowns is not None else _NO_TREES
    x["smask"] = _sun_masks(geo, crowns)
    x["bmask"] = _building_masks(geo, scene, cfg, clock) if cfg.sun_masks else _NO_BMASK
    sky_x = geo.get("sky_x")
    if perez and sky_x is not None and sky_x.shape[1]:
        # the sky tables of the passes' days only (*times*: when each pass looks them up)
        tables = radiation_table.sky_window(times)
        x.update(sky_cell=_writable(geo["sky_cell"]), sky_f=_writable(geo["sky_f"]),
                 sky_t=_writable(geo["sky_t"]), sky_tilted=_writable(geo["sky_tilted"]),
                 sky_rows=_writable(tables["rows"]), sky_packed=_writable(tables["packed"]),
                 sky_open=(_writable(tables["all_open"]), _writable(tables["clear_open"])),
                 sky_t0=tables["t0"], sky_step=tables["step"],
                 ts=tuple(_writable(geo[k]) for k in ("tsky_off", "tsky_cell", "tsky_sector", "tsky_w")))
        x["has_sky"] = True
    else:
        x["has_sky"] = False
        e2 = np.zeros((0, 2), f32)
        x.update(sky_cell=np.zeros((n_seg, 0), np.int64), sky_f=np.zeros((n_seg, 0), f32),
                 sky_t=np.zeros((n_seg, 0), f32), sky_tilted=np.zeros(n_seg, np.bool_),
                 sky_rows=np.zeros((1, 0), np.int32),
                 sky_packed=np.zeros((SKY_AZIMUTH_BINS * (SKY_LEVELS + 1) * SKY_PACK, 0), f32),
                 sky_open=(e2, e2), sky_t0=0.0, sky_step=1.0,
                 ts=(np.zeros(n_seg + 1, np.int64), _NO_INT, _NO_INT, np.zeros((0, C), f32)))
    return x


def _sun_masks(geo: dict, crowns) -> np.ndarray:
    """The sun masks of the geometry's roof points among *crowns*
    (:meth:`vipvflow.models.trees.Crowns.sun_masks`), kept in *geo* for the crowns they were
    made for (a tile's packed geometry lives for many partitions); (0, sectors) without crowns."""
    if crowns is None:
        return np.zeros((0, MASK_SECTORS))
    kept = geo.get("_sun_masks")
    if kept is not None and kept[0] is crowns:
        return kept[1]
    masks = crowns.sun_masks(geo["p_local"])
    geo["_sun_masks"] = (crowns, masks)
    return masks


#: no sun masks among the buildings: every sun ray is cast
_NO_BMASK = np.zeros((0, BUILDING_SECTORS))


def _building_masks(geo: dict, scene, cfg, clock: dict | None = None) -> np.ndarray:
    """The sun masks of the geometry's roof points among *scene*'s buildings for rays of
    ``cfg.ray_length_m`` (:meth:`vipvflow.models.shading.Scene.sun_masks`), kept in *geo*
    for the scene and length they were made for; none without a scene.  The seconds of a
    build are added to ``clock["sun_masks_s"]``."""
    if scene is None or not hasattr(scene, "sun_masks"):
        return _NO_BMASK
    kept = geo.get("_building_masks")
    if kept is not None and kept[0] is scene and kept[1] == cfg.ray_length_m:
        return kept[2]
    t = time.perf_counter()
    masks = scene.sun_masks(geo["p_local"], cfg.ray_length_m)
    if clock is not None:
        clock["sun_masks_s"] = clock.get("sun_masks_s", 0.0) + time.perf_counter() - t
    geo["_building_masks"] = (scene, cfg.ray_length_m, masks)
    return masks


#: the crowns' arrays of a scene without trees (:meth:`vipvflow.models.trees.Crowns.arrays`)
_NO_TREES = (np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0),
             np.array([0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0]), np.zeros(2, np.int64),
             np.zeros(0, np.int64), np.ones((0, 1), np.float32))


def _run(seg, t_start, dt, mid, row, geo, cfg, radiation_table, scene, loc_of_row, clock,
         finish):
    """Chunks of passes through setup -> Embree -> *finish(lo, hi, x, batch, occ, P, rotate)*."""
    x = _inputs(geo, cfg, radiation_table, loc_of_row, _time_span(t_start, dt, mid), scene, clock)
    J, P, rotate, per_pass, chunk = _plan(geo, cfg)
    n = len(row)
    chunk = min(chunk, max(n, 1))
    bt = _Batch(chunk, per_pass, max(J, 1))
    rw = np.float32(ROULETTE_WEIGHT)
    for lo in range(0, n, chunk):
        hi = min(n, lo + chunk)
        t_a = time.perf_counter()
        nr, _ = _setup(lo, hi, seg, t_start, dt, mid, row, x["loc"], x["packed"], x["cols"],
                       x["t0"], x["step"], x["nrm"], x["wn"], x["tree_month"], x["p_local"],
                       x["gp_local"], rotate, rw, x["perez"], x["sky_rows"], x["sky_t0"],
                       x["sky_step"], x["bmask"], bt.rad, bt.cos_aoi, bt.pass_ray, bt.pair_w,
                       bt.pair_pass, bt.pair_pt, bt.o, bt.d, bt.done, bt.free)
        t_b = time.perf_counter()
        occ = (scene.occluded_local(bt.o[:nr], bt.d[:nr], cfg.ray_length_m) if nr
               else np.zeros(0, bool))
        t_c = time.perf_counter()
        if x["has_sky"]:
            _sky_terms(lo, hi, row, bt.rad, bt.done, x["sky_cell"], x["sky_f"], x["sky_t"],
                       x["sky_tilted"], x["sky_packed"], x["sky_open"][0], x["sky_open"][1],
                       x["nrm"], x["ts"], SKY_GRID_BUDGET, bt.terms)
        finish(lo, hi, x, bt, occ, P, rotate)
        t_d = time.perf_counter()
        clock["ray_setup_s"] = clock.get("ray_setup_s", 0.0) + t_b - t_a
        clock["rays_s"] = clock.get("rays_s", 0.0) + t_c - t_b
        clock["components_s"] = clock.get("components_s", 0.0) + t_d - t_c
        # sun rays in front of the roof: cast, or told clear by the masks (counts, not s)
        m = hi - lo
        masked = int(np.count_nonzero(bt.free[:m]))
        clock["sun_rays_masked_n"] = clock.get("sun_rays_masked_n", 0) + masked
        clock["sun_rays_cast_n"] = (clock.get("sun_rays_cast_n", 0)
                                    + int(np.count_nonzero(bt.cos_aoi[:m] > 0)) - masked)


def _time_span(t_start, dt, mid) -> np.ndarray:
    """Times no later than the first and no earlier than the last of the passes' radiation
    times (``t_start + dt / 2`` with *mid*, as :func:`_setup` takes them; NaN left out); none
    without passes."""
    if not len(t_start):
        return np.zeros(0)
    lo, hi = np.fmin.reduce(t_start), np.fmax.reduce(t_start)
    if mid and len(dt):
        lo = lo + 0.5 * min(0.0, np.fmin.reduce(dt))
        hi = hi + 0.5 * max(0.0, np.fmax.reduce(dt))
    return np.array([lo, hi], np.float64)


def evaluate_block(seg, t_start, dt, mid, row, geo, cfg, radiation_table, scene,
                   loc_of_row=None, timings: dict | None = None):
    """Per-pass components of the fused kernel (:func:`vipvflow.models.irradiance.evaluate_passes`).

    Parameters
    ----------
    seg : (n,) int64, segment id of each pass (the reflector sample key)
    t_start : (n,) float64, Unix s at the segment start
    dt : (n,) float64, s on the segment (used when *mid*: radiation at ``t_start + dt / 2``)
    mid : bool
    row : (n,) int64, row of each pass's segment in the packed geometry *geo*
    geo : dict from :func:`vipvflow.models.view_factors.pack_geometry` with a scene (local frame)
    cfg : IrradianceCfg
    radiation_table : vipvflow.models.sun_sky.RadiationTable
    scene : vipvflow.models.shading.Scene
    loc_of_row : (segments,) int64, optional, radiation location of each geometry row
    timings : dict, optional, seconds added to ``ray_setup_s`` (includes the radiation
        lookup), ``rays_s``, ``components_s`` and ``sun_masks_s`` (a tile's masks, once),
        and the counts ``sun_rays_cast_n`` and ``sun_rays_masked_n`` (sun rays in front of
        the roof told clear by the masks, with no ray)

    Returns
    -------
    block : (n, 14) float32, W/m2, columns :data:`BLOCK_COLUMNS`
    visible : (n,) bool, the sun ray from the roof point was free
    """
    seg, t_start, dt, row = (_writable(a) for a in (seg, t_start, dt, row))
    n = len(row)
    block = np.zeros((len(BLOCK_COLUMNS), n), np.float32)      # one row per column
    visible = np.zeros(n, bool)

    finish = _finisher(row, dt, False, block, visible, _NO_INT, _NO_INT, _NO_BINS, _NO_BINS)
    _run(seg, t_start, dt, mid, row, geo, cfg, radiation_table, scene, loc_of_row,
         {} if timings is None else timings, finish)
    return block.T, visible


def accumulate(seg, t_start, dt, mid, row, geo, cfg, radiation_table, scene, seg_hour, n_seg_hour,
               run, n_runs, loc_of_row=None, timings: dict | None = None, seg_bins=None):
    """Irradiation of every pass summed into bins, without per-pass outputs.

    Parameters
    ----------
    seg, t_start, dt, mid, row, geo, cfg, radiation_table, scene, loc_of_row, timings :
        as in :func:`evaluate_block`
    seg_hour : (n,) int64, bin of each pass (segment x 24 + local hour), < *n_seg_hour*
    run : (n,) int64, (trip, service date) run of each pass, < *n_runs*
    seg_bins : (n_seg_hour, 14) float64, optional, the bins of earlier passes, which these
        passes are added to, pass after pass (a partition's passes in chunks: the sums of
        all at once, bit for bit); default new bins of zeros

    Returns
    -------
    seg_bins : (n_seg_hour, 14) float64, Wh/m2 per (segment, local hour), :data:`BLOCK_COLUMNS`
    run_bins : (n_runs, 14) float64, Wh/m2 per run
    """
    seg, t_start, dt, row, seg_hour, run = (_writable(a) for a in (seg, t_start, dt, row, seg_hour, run))
    if seg_bins is None:
        seg_bins = np.zeros((n_seg_hour, len(BLOCK_COLUMNS)))
    elif seg_bins.shape != (n_seg_hour, len(BLOCK_COLUMNS)) or not seg_bins.flags.c_contiguous:
        raise ValueError(f"seg_bins must be C-contiguous ({n_seg_hour}, {len(BLOCK_COLUMNS)})")
    run_bins = np.zeros((n_runs, len(BLOCK_COLUMNS)))

    finish = _finisher(row, dt, True, _NO_BLOCK, _NO_VISIBLE, seg_hour, run, seg_bins, run_bins)
    _run(seg, t_start, dt, mid, row, geo, cfg, radiation_table, scene, loc_of_row,
         {} if timings is None else timings, finish)
    return seg_bins, run_bins


def _finisher(row, dt, to_bins, block, visible, seg_hour, run, seg_bins, run_bins):
    """The last step :func:`_run` calls on each chunk: :func:`_finish` into *block* and
    *visible*, or (*to_bins*) into *seg_bins* and *run_bins*."""
    def finish(lo, hi, x, bt, occ, P, rotate):
        _finish(lo, hi, row, bt.rad, bt.cos_aoi, bt.pass_ray, bt.pair_w, bt.pair_pass,
                bt.pair_pt, x["gf"], occ, bt.done, bt.free, x["p_local"], x["sky"], x["sky_nt"], x["iso"], x["refl_sky"], x["refl_ghi"],
                x["perez"], x["hbv"], x["hbv_nt"], x["refl_hor"], x["sin_tilt"], x["has_sky"],
                bt.terms, rotate, P, bt.o, bt.d, x["tmax"], x["tr"], x["smask"], to_bins, block, visible, dt,
                seg_hour, run, seg_bins, run_bins)
    return finish


def warm() -> float:
    """Compile (or load from the on-disk cache) the kernels for the types a run passes;
    returns the seconds it took."""
    t = time.perf_counter()
    f32, i64 = np.float32, np.int64
    one_i, one_f, one_t = np.zeros(1, i64), np.zeros(1, f32), np.zeros(1)
    one_c = np.zeros((1, 1), f32)
    rad, pr = np.zeros((1, _N_ROW), f32), np.zeros(2, i64)
    o3 = np.zeros((1, 3), f32)
    packed = np.zeros((1, 2, _N_RAD), f32)
    tables = np.zeros((1, SKY_AZIMUTH_BINS * (SKY_LEVELS + 1)), f32)
    months = np.zeros((1, 12), i64)
    ts = (np.zeros(2, i64), np.zeros(0, i64), np.zeros(0, i64), np.zeros((0, 1), f32))
    for rotate in (True, False):
        for perez in (True, False):
            for n_sky in (0, SKY_AZIMUTH_BINS):
                rows = np.zeros((1, 2 if n_sky else 0), np.int32)
                _setup(0, 1, one_i, one_t, one_t, True, one_i, one_i, packed,
                       np.arange(_N_RAD, dtype=i64), 0.0, 60.0, o3, np.zeros((1, 1, 1, 3), f32),
                       months, o3, np.zeros((1, 1, 3), f32), rotate, f32(0.02), perez, rows, 0.0,
                       900.0, _NO_BMASK, rad, one_f, pr, one_f, one_i, one_i, o3, o3,
                       np.zeros(1, np.bool_), np.zeros(1, np.bool_))
                for to_bins in (False, True):
                    _finish(0, 1, one_i, rad, one_f, pr, one_f, one_i, one_i, one_c, np.zeros(1, bool),
                            np.zeros(1, np.bool_), np.zeros(1, np.bool_), o3, one_c, one_f, one_f, one_c, one_c, perez, one_c,
                            one_f, one_c, one_f, bool(n_sky), np.zeros((1, 6), f32), rotate, 1, o3,
                            o3, 300.0, _NO_TREES, np.zeros((1, MASK_SECTORS)), to_bins,
                            np.zeros((_NB, 1), f32),
                            np.zeros(1, bool), one_t, one_i, one_i, np.zeros((1, _NB)),
                            np.zeros((1, _NB)))
    _sky_terms(0, 1, one_i, rad, np.zeros(1, np.bool_), np.zeros((1, SKY_AZIMUTH_BINS), np.int64),
               np.zeros((1, SKY_AZIMUTH_BINS), f32), np.zeros((1, SKY_AZIMUTH_BINS), f32),
               np.zeros(1, np.bool_), np.zeros((tables.shape[1] * SKY_PACK, 1), f32),
               np.zeros((1, 2), f32), np.zeros((1, 2), f32), o3, ts, 1 << 20, np.zeros((1, 6), f32))
    _groups(one_i, one_i, one_i, one_t, one_t, 0, one_i, 0, one_t, one_i, one_i, one_i, one_i)
    building_masks(np.zeros((1, 3, 3), f32), one_t, np.zeros((1, 4)), o3, 300.0, MASK_FLOOR,
                   np.zeros((1, BUILDING_SECTORS)))
    _seconds(one_i, one_i, one_i, one_t, one_t, one_t, one_t, one_i, one_i)
    return time.perf_counter() - t
