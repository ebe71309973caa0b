"""Mitsuba 3 twin of vs_mitsuba_sphere.toml, timed by vs_mitsuba.sh.

512x512 orthographic camera spanning 2.2 world units, a unit sphere with a
polarized diffuse dielectric (albedo 0.8, eta 1.5, no specular), one
directional light of irradiance 3 from (0.4, 0.3, 1), 64 spp. Our
`max_depth` counts surface interactions, Mitsuba's counts path segments
(1 = emitters seen directly), so ours 4 is Mitsuba's 5. Writes the Stokes
image as EXR.

usage: python vs_mitsuba_sphere.py OUT.exr [SPP] [SIZE]
"""
import sys

import mitsuba as mi

mi.set_variant("llvm_ad_mono_polarized")

out = sys.argv[1]
spp = int(sys.argv[2]) if len(sys.argv) > 2 else 64
size = int(sys.argv[3]) if len(sys.argv) > 3 else 512
scene = mi.load_dict({
    "type": "scene",
    "integrator": {"type": "stokes", "integrator": {"type": "path", "max_depth": 5}},
    "sensor": {
        "type": "orthographic",
        "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0])
        @ mi.ScalarTransform4f().scale([1.1, 1.1, 1.0]),
        "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}},
        "sampler": {"type": "independent", "sample_count": spp, "seed": 1},
    },
    "sphere": {
        "type": "sphere",
        "center": [0, 0, 0],
        "radius": 1.0,
        "bsdf": {
            "type": "pplastic",
            "diffuse_reflectance": {"type": "rgb", "value": 0.8},
            "specular_reflectance": {"type": "rgb", "value": 0.0},
            "int_ior": 1.5,
            "ext_ior": 1.0,
        },
    },
    "light": {
        "type": "directional",
        "direction": [-0.4, -0.3, -1.0],
        "irradiance": {"type": "rgb", "value": 3.0},
    },
})
image = mi.render(scene)
mi.Bitmap(image).write(out)
