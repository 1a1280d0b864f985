"""
The albedo of a BRDF
====================

The directional albedo a(mu) is the fraction of the light arriving from cos(theta_i) = mu that a BRDF reflects
(000 eq. 2). Reciprocal Phong loses energy at grazing incidence; stretched Phong (000 eq. 7) keeps its albedo near
1; the microfacet GGX model loses what its single-scattering lobe cannot reflect.
"""

import matplotlib.pyplot as plt
import numpy as np

import pumpup

mu = np.cos(np.radians(np.linspace(0.0, 89.5, 90)))
fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
for spec in ("phong:n=20", "stretched_phong:n=20", "ggx:alpha=0.3", "ward:m=0.1"):
    f = pumpup.load(spec)
    a, err = pumpup.albedo(f, mu, return_error=True)
    print(f"{spec:22s} a(1) = {a[0]:.6f}, a(89.5 deg) = {a[-1]:.6f}, largest error estimate {err.max():.1e}")
    ax.plot(np.degrees(np.arccos(mu)), a, label=spec)
ax.set(xlabel="incidence angle theta_i [deg]", ylabel="directional albedo a(mu)", ylim=(0, 1.3))
ax.axhline(1.0, color="gray", lw=0.8)
ax.legend()
ax.grid(alpha=0.3)

# %%
# Ward's model reflects more than it receives near grazing incidence: its albedo diverges like mu^(-1/2)
# (001 sec. 2.1), which ``pumpup divergence ward:m=0.1`` measures.
