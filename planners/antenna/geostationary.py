"""Look angles from a ship to a geostationary satellite: azimuth, elevation, polarization.

So a scenario can name a satellite (its orbital longitude) and the ship's position instead of
angles. The ship's position on the WGS84 ellipsoid comes from pyerfa (``gd2gc``); the
satellite sits on the equator at the geostationary radius. The look vector is rotated into the
ship's East-North-Up frame:

  azimuth = atan2(east, north) (clockwise from north), elevation = asin(up / range).

Polarization. The satellite transmits linearly polarized waves whose E-field is either
parallel to the Earth's axis ("vertical") or to the equatorial plane ("horizontal"). The
antenna's polarization angle sigma is the paper's sigma_e of eq. (1): the angle about the
boresight from the Y_s axis at sigma = 0 (the local horizontal in the aperture plane, see
``planbench.planners.antenna.satellite_attitude``) to the received E-field. For horizontal polarization
it is minus the polarization skew of Maral & Bousquet (Satellite Communications Systems,
5th ed., sec. 8.3.3), tan(psi) = sin(dLambda) / tan(lat) with dLambda = satellite minus ship
longitude, for a spherical Earth (their psi is counted the other way round the boresight);
the tests compare the two. Elevation and azimuth are compared with the same book's spherical
formulas, cos(gamma) = cos(lat) cos(dLambda).
"""

from __future__ import annotations

import numpy as np

from planbench.planners.antenna import satellite_attitude
from planbench.planners.errors import LimitError, PlanningError

GEO_RADIUS = 42_164_172.0  # m: (mu / Omega^2)^(1/3) with mu = 3.986004418e14, sidereal day
POLARIZATIONS = ("horizontal", "vertical")


def _enu_basis(lat: float, lon: float) -> np.ndarray:
    """Rows: East, North, Up unit vectors (geodetic) in Earth-fixed coordinates."""
    sl, cl, sp, cp = np.sin(lon), np.cos(lon), np.sin(lat), np.cos(lat)
    return np.array([[-sl, cl, 0.0], [-sp * cl, -sp * sl, cp], [cp * cl, cp * sl, sp]])


def look_angles(
    satellite_lon: float, lat: float, lon: float, height: float = 0.0, polarization: str = "horizontal"
) -> tuple[float, float, float]:
    """(azimuth, elevation, polarization) in rad from a ship to a geostationary satellite.

    Args:
      satellite_lon: the satellite's orbital longitude, rad (east positive).
      lat, lon: the ship's geodetic latitude and longitude, rad (WGS84).
      height: the antenna's height above the ellipsoid, m.
      polarization: "horizontal" or "vertical", the satellite's linear polarization.
    Raises LimitError when the satellite is below the horizon.
    """
    import erfa  # pyerfa: WGS84 geodetic -> Earth-fixed position

    for name, value in (
        ("satellite longitude", satellite_lon),
        ("latitude", lat),
        ("longitude", lon),
        ("height", height),
    ):
        if not np.isfinite(value):
            raise PlanningError(f"{name} {value!r} must be finite")
    if abs(lat) > np.pi / 2:
        raise PlanningError(f"latitude {np.degrees(lat):.3f} deg is beyond +/-90 deg")
    if polarization not in POLARIZATIONS:
        raise PlanningError(f"polarization {polarization!r} is not one of {', '.join(POLARIZATIONS)}")
    ship = np.asarray(erfa.gd2gc(1, lon, lat, height))
    satellite = GEO_RADIUS * np.array([np.cos(satellite_lon), np.sin(satellite_lon), 0.0])
    enu = _enu_basis(lat, lon)
    look = enu @ (satellite - ship)
    distance = np.linalg.norm(look)
    elevation = float(np.arcsin(look[2] / distance))
    if elevation < 0.0:
        raise LimitError(
            f"the satellite at {np.degrees(satellite_lon):.2f} deg is {np.degrees(elevation):.2f} deg "
            f"below the horizon of a ship at ({np.degrees(lat):.2f}, {np.degrees(lon):.2f}) deg; "
            f"the limit is 0 deg"
        )
    azimuth = float(np.arctan2(look[0], look[1]) % (2.0 * np.pi))
    # The E-field in ENU, projected on the aperture plane (perpendicular to the boresight).
    field = enu @ (
        np.array([0.0, 0.0, 1.0])
        if polarization == "vertical"
        else np.array([-np.sin(satellite_lon), np.cos(satellite_lon), 0.0])
    )
    frame = satellite_attitude(azimuth, elevation, 0.0)
    y0, boresight = frame[:, 1], frame[:, 2]
    field = field - (field @ boresight) * boresight
    sigma = float(np.arctan2(np.cross(y0, field) @ boresight, y0 @ field))
    # A linear polarization is a line: take the angle in (-90, 90] deg.
    sigma = (sigma + np.pi / 2) % np.pi - np.pi / 2
    if sigma == -np.pi / 2:
        sigma = np.pi / 2
    return azimuth, elevation, sigma
