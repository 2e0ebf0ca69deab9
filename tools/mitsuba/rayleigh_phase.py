"""Polarized Rayleigh phase function for Mitsuba 3, registered from Python as
the phase plugin `rayleigh_polarized` (Mitsuba 3.9's own `rayleigh` ignores
polarization: it warns and returns the scalar phase function).

The dipole scattering matrix (van de Hulst 1957; Bohren & Huffman 1983,
eq. 5.7 normalised to a phase function), with mu = cos(scattering angle)
and both Stokes frames' x axis n = normalize(k_in x k_out), the normal of
the scattering plane (y = k x n, Mitsuba's right-handed (x, y, k)):

    M = 3 / (16 pi) [[1 + mu^2, 1 - mu^2, 0,    0   ],
                     [1 - mu^2, 1 + mu^2, 0,    0   ],
                     [0,        0,        2 mu, 0   ],
                     [0,        0,        0,    2 mu]]

M[0, 0] is Mitsuba's (and the textbook) Rayleigh phase function. An
unpolarized beam scattered by 90 degrees leaves with DoLP 1, by 45 degrees
with DoLP (1 - mu^2) / (1 + mu^2) = 1/3, polarized along n (perpendicular
to the scattering plane).

Frames and directions. Mitsuba multiplies the path throughput by the
phase value as it is (`volpath`: `throughput * phase_val * emitted`, with no
frame handling, unlike surfaces where it calls `si.to_world_mueller`), so
the matrix must map the implicit world Stokes frame of the incident light
(`mueller.stokes_basis(k_in)`) to that of the scattered light
(`stokes_basis(k_out)`). In radiance mode (camera paths) `mei.wi` points
from the vertex back toward the camera, i.e. along the scattered light,
k_out = mei.wi, and `wo` toward the light, k_in = -wo: the same
convention as Mitsuba's BSDFs (`to_world_mueller(M, -wo, wi)`).
Importance mode (light tracing) is refused when the kernel is traced.
"""

PLUGIN = "rayleigh_polarized"


def rayleigh_mueller(mi, dr, k_in, k_out):
    """The Mueller matrix above, re-expressed from the scattering-plane frames
    to Mitsuba's implicit frames stokes_basis(k_in) -> stokes_basis(k_out)."""
    mu = dr.clip(dr.dot(k_in, k_out), -1.0, 1.0)
    n = dr.cross(k_in, k_out)
    norm = dr.norm(n)
    # Forward or backward scattering: any n perpendicular to k_in (both frames
    # share it, and M is then diagonal), here k_in's own Stokes basis.
    n = dr.select(norm > 1e-6, n / dr.maximum(norm, 1e-30), mi.mueller.stokes_basis(k_in))
    c = 3.0 / (16.0 * dr.pi)
    m = dr.zeros(mi.Spectrum)
    m[0, 0] = m[1, 1] = c * (1.0 + mu * mu)
    m[0, 1] = m[1, 0] = c * (1.0 - mu * mu)
    m[2, 2] = m[3, 3] = c * 2.0 * mu
    return mi.mueller.rotate_mueller_basis(
        m,
        k_in, n, mi.mueller.stokes_basis(k_in),
        k_out, n, mi.mueller.stokes_basis(k_out),
    )


def rayleigh_pdf(dr, mu):
    """The scalar Rayleigh phase function 3 / (16 pi) (1 + mu^2), per steradian."""
    return 3.0 / (16.0 * dr.pi) * (1.0 + mu * mu)


def sample_rayleigh_cosine(dr, u):
    """mu with density proportional to 1 + mu^2 on [-1, 1] from uniform u.

    The CDF (mu^3 + 3 mu + 4) / 8 = u is a depressed cubic with one real root
    (Cardano): mu = cbrt(q + r) + cbrt(q - r), q = 4 u - 2, r = sqrt(q^2 + 1).
    """
    q = 4.0 * u - 2.0
    r = dr.sqrt(q * q + 1.0)
    return dr.clip(dr.cbrt(q + r) + dr.cbrt(q - r), -1.0, 1.0)


def register(mi, dr):
    """Registers `rayleigh_polarized` with the current Mitsuba variant (idempotent)."""

    class RayleighPolarized(mi.PhaseFunction):
        """Rayleigh phase function with the dipole Mueller matrix (module doc)."""

        def __init__(self, props):
            mi.PhaseFunction.__init__(self, props)
            self.m_flags = mi.PhaseFunctionFlags.Anisotropic

        @staticmethod
        def _radiance_only(ctx):
            if ctx.mode != mi.TransportMode.Radiance:
                raise NotImplementedError(f"{PLUGIN}: only radiance transport (camera paths) is implemented")

        def eval_pdf(self, ctx, mei, wo, active=True):
            self._radiance_only(ctx)
            k_in, k_out = -wo, mei.wi
            value = rayleigh_mueller(mi, dr, k_in, k_out)
            return value, rayleigh_pdf(dr, dr.dot(k_in, k_out))

        def sample(self, ctx, mei, sample1, sample2, active=True):
            self._radiance_only(ctx)
            mu = sample_rayleigh_cosine(dr, sample2.x)
            sin_t = dr.safe_sqrt(1.0 - mu * mu)
            sin_p, cos_p = dr.sincos(2.0 * dr.pi * sample2.y)
            # k_in makes the angle acos(mu) with k_out = wi; wo = -k_in.
            k_in = mi.Frame3f(mei.wi).to_world(mi.Vector3f(sin_t * cos_p, sin_t * sin_p, mu))
            pdf = rayleigh_pdf(dr, mu)
            weight = rayleigh_mueller(mi, dr, k_in, mei.wi) / pdf
            return -k_in, weight, pdf

        def to_string(self):
            return "RayleighPolarized[]"

    mi.register_phase(PLUGIN, lambda props: RayleighPolarized(props))
