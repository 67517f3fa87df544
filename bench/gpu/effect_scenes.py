# Copies of scenes/bench_realistic.yaml with keys taken out, each realistic effect added in
# turn (bench/gpu/run.sh; the tables of bench/baselines/camera-pixels-2core.md):
#   scenes/_e1_vignetting.yaml  lens and cos^4 vignetting, no noise
#   scenes/_e2_bayer.yaml       + RGGB filter, edge-aware demosaic, sRGB
#   scenes/_e3_emva.yaml        + the IMX174 EMVA sensor (no depth of field)
import re
src = open("scenes/bench_realistic.yaml").read()
lens_full = re.compile(r"lens: \{vignetting: cos4,[^}]*\}")
steps = {
    "_e1_vignetting": ("emva", "color", "dof"),
    "_e2_bayer": ("emva", "dof"),
    "_e3_emva": ("dof",),
}
for name, drop in steps.items():
    t = src
    if "emva" in drop:
        t = re.sub(r"\n\s*emva: \{preset: imx174\}", "", t)
    if "color" in drop:
        t = re.sub(r"\n\s*color: \{cfa: rggb[^}]*\}", "", t)
    if "dof" in drop:
        t = lens_full.sub("lens: {vignetting: cos4}", t)
    assert t != src
    open(f"scenes/{name}.yaml", "w").write(t)
