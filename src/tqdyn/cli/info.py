"""Command line: ``tqdyn info``: versions, built-in scenarios, integrator
tableaux, force models and their sources.

Registered in :mod:`tqdyn.cli` with ``cli.add_command(info)``.
"""

from __future__ import annotations

import click

from .._version import __version__

__all__ = ["info"]


@click.command("info")
def info():
    """Versions, built-in scenarios, integrator tableaux, force models, their
    sources, and the Earth-orientation sources with their spans."""
    import platform
    from importlib import resources

    from ..astro.eop_sources import describe_sources
    from ..astro.reference import REFERENCE_SYSTEMS
    from ..forces.model import describe_terms
    from ..numerics.dp87 import CORRECTED_TABLEAU_PROVENANCE
    from ..numerics.multistep import CORRECTORS, ORDERS
    from ..scenario import DEFAULT_METHOD, builtin_scenarios

    def version(mod):
        try:
            return __import__(mod).__version__
        except ImportError:
            return "not installed"

    lines = [f"tqdyn {__version__} (Python {platform.python_version()}, {platform.machine()})",
             "libraries: " + ", ".join(f"{m} {version(m)}" for m in
                                       ("numpy", "numba", "mpmath", "erfa", "h5py", "xarray", "heyoka",
                                        "astropy_iers_data")),
             "built-in scenarios: " + ", ".join(builtin_scenarios()),
             "reference systems (scenario.central_body):",
             *(f"  {r.central_body:<6} {r.frame}, t in {r.time_scale}: {r.description}" for r in REFERENCE_SYSTEMS),
             "precision: dd (compiled double-double, ~32 digits, FMA two-product) | float64",
             f"integrator (integrator.method; not given: {DEFAULT_METHOD} with a fixed step, dp87 adaptive):",
             "  dp87: Prince-Dormand RK8(7)13M, fixed step or adaptive (embedded 7th order), Hermite dense output",
             f"    tableaux: corrected (default; {CORRECTED_TABLEAU_PROVENANCE}) | published "
             "(GSL rk8pd.c / GMAT rationals, order conditions hold to ~6.5e-18)",
             "  multistep: Gauss-Jackson / summed Adams, fixed step, order "
             f"{ORDERS[0]}..{ORDERS[-1]}, {' | '.join(CORRECTORS)}, DP87 start-up",
             "force models:"]
    for name, description, source in describe_terms():
        lines.append(f"  {name:<20} {description} [{source}]")
    data = resources.files("tqdyn") / "data"
    lines.append(f"shipped data ({data}; provenance in SOURCES.md):")
    for entry in sorted(p.name for p in data.iterdir() if p.name != "SOURCES.md"):
        lines.append(f"  {entry}")
    lines.append("ephemeris: DE421 from the skyfield-data package (any JPL DE file by path: forces.ephemeris)")
    lines += describe_sources()
    lines += [
        "constellation (coupled dynamics, [constellation] / [spacecraft] in a scenario):",
        "  pointing laws: global (instantaneous plane) | taylor1, taylor2 (light-time Taylor expansion) |"
        " iterative (light-time equation solved exactly); none = independent point masses",
        "  control: on (drag-free G_i in the orbits, suspension A_c,l from the three conditions: scheme tianqin"
        " eq. E1/E2 with tan/cot of theta/2, scheme lisa the same conditions for any independent sensitive axes) | off (pure-gravity orbits); free_tms: TMs as free bodies (verification)",
        "  spacecraft: architecture presets tianqin (default; drag-free scheme tianqin, the paper's closed form) |"
        " lisa, taiji (one TM per MOSA on its optical axis, MOSAs turning about Z_S through the CoM; scheme lisa);"
        " dragfree = tianqin | lisa overrides the scheme",
        "    tianqin only: d_tm (TMs +/-d_tm/2 along tm_axis of S, default 0.40 m along y), d_p (pivots behind the"
        " EH centres, default 0 m); lisa/taiji only: tm_distance (EH centre from the CoM along the optical axis,"
        " default 0.30 m)",
        "    any architecture: housing_centers, pivots ([[x, y, z], [x, y, z]] m in S at 60 deg), sensitive_axes"
        " (unit vectors in OA_l, default X_OA_l), envelope_radius (m, default 1.5); DC self-gravity per TM in"
        " OA_l (Table IV of the paper by default) + a common part fixed in S",
        "  trajectory files of coupled runs record spacecraft_architecture, dragfree_scheme and the"
        " spacecraft_* geometry (docs/trajectory-format.md)",
    ]
    click.echo("\n".join(lines))
