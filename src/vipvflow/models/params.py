"""The models' own parameters: what the physics and the vehicle model take, validated.

The configuration (:mod:`vipvflow.config`) reads the scenario files and builds these; the
models import them from here and never read the configuration themselves.
"""
from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator


class _Params(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_assignment=True, allow_inf_nan=False)


class CycleCfg(_Params):
    dt_s: float = Field(2.0, gt=0)
    max_accel_mps2: float = Field(1.0, gt=0)
    max_decel_mps2: float = Field(1.3, gt=0)
    speed_limit_kmh: float = Field(50.0, gt=0)
    dwell_s: float = Field(20.0, ge=0)


class TreeCfg(_Params):
    """How tree crowns shade the roofs (:mod:`vipvflow.models.trees`).

    A crown transmits ``transmittance_leaf_on`` of the light crossing it while in leaf and a
    deciduous one ``transmittance_leaf_off`` in its leaf-off months (a ray through several
    crowns: the product).  Defaults from measurements of single urban trees: in leaf 0.088 to
    0.275 (Konarska et al. 2014), a sugar maple's shade 80 % darker in leaf and nearly 40 %
    leafless (Heisler 1986).
    """

    # false: the city's trees are ignored (the buildings alone shade)
    enabled: bool = True
    transmittance_leaf_on: float = Field(0.20, ge=0, le=1)
    transmittance_leaf_off: float = Field(0.60, ge=0, le=1)
    # months (1..12) deciduous trees stand leafless; null: November to April north of the
    # equator, May to October south of it (a tree's own leaf_off_months win)
    leaf_off_months: list[int] | None = None
    # trees whose data names no leaf type
    unknown_leaf_type: Literal["deciduous", "evergreen"] = "deciduous"

    @field_validator("leaf_off_months")
    @classmethod
    def _months(cls, v):
        if v is not None and any(not 1 <= m <= 12 for m in v):
            raise ValueError(f"leaf_off_months are months 1..12, got {v}")
        return None if v is None else sorted(set(v))


class IrradianceCfg(_Params):
    # perez_svf (default): the Perez (1993) sky's light over the sky the roof point sees
    # (its horizon per 10 deg sector), the reflectors lit by the three-part Perez (1990) sky;
    # sky_view_factor: DHI x the roof point's cosine-weighted sky view (a uniform sky);
    # isotropic: the paper's DHI (1 + cos tilt) / 2, an upper bound in streets
    diffuse_model: Literal["perez_svf", "isotropic", "sky_view_factor"] = "perez_svf"
    reflection: bool = True
    reflection_rays: int = Field(256, ge=0, le=65_536)
    svf_rays: int = Field(512, gt=0, le=65_536)
    ray_length_m: float = Field(300.0, gt=0, le=100_000)
    # per roof point and 1 deg of azimuth, a bound on how high the buildings rise: a sun
    # ray above it is clear without Embree (exact: the same answer; false casts every ray)
    sun_masks: bool = True
    ray_offset_m: float = Field(0.05, ge=0)
    max_reflector_groups: int = Field(4, ge=0)
    reflector_points: int = Field(64, ge=1)
    reflector_sampling: Literal["rotate", "all"] = "rotate"
    reflector_sky_rays: int = Field(4, ge=1)
    horizon_band_rays: int = Field(64, ge=1, le=65_536)
    # where the city model has no ground (no terrain, no road surfaces) the street under the
    # bus is the level ground at the road's height, lit and shaded as it is, with the road's
    # albedo; false: rays that leave the model downwards see an open field lit by GHI
    virtual_street: bool = True
    # the city's trees (CityGML vegetation, inputs.trees): crowns with a transmittance by season
    trees: TreeCfg = Field(default_factory=TreeCfg)
    seed: int = 7


class PVSystem(_Params):
    """A PV system on the bus roof (catalog entry of ``conf/pv_systems.yaml``)."""

    name: str = ""
    technology: str = "c-Si"
    kwp: float = Field(gt=0)
    roof_area_m2: float = Field(gt=0)
    area_share: float = Field(gt=0, le=1)
    performance_ratio: float = Field(gt=0, le=1)
    gamma_pdc_per_k: float = -0.0037
    inverter_efficiency: float = Field(0.96, gt=0, le=1)
    system_losses_percent: float = Field(14.0, ge=0, lt=100)
    temperature_model: str = "sapm_open_rack_glass_polymer"
