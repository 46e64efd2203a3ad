# ParaView and animation output (ncd/io/export.py): `snakemake -j2 export`, not part of the
# default target.  For each figure whose data file stores frames (fig2_slope: the flow,
# every `flow.snapshot_every` steps; fig4_pile: the pile's construction, every
# `construction.frame_every` steps, with the ground discs in <name>_ground.vtu; fig4_history:
# pile 0 of each history, as fig4_history_point and fig4_history_rain):
#   results/<figure>/vtk/<name>_discs.pvd, <name>_contacts.pvd (+ one .vtu per frame)
#   results/figures/<figure>.mp4  (animated .gif instead when ffmpeg is absent)
import shutil

ANIM_EXT = "mp4" if shutil.which("ffmpeg") else "gif"
# figure: (data file with a `frame` dimension, name of the series)
EXPORTS = {f: v for f, v in {"fig2_slope": ("results/fig2_slope/trajectory.nc", "flow"),
                             "fig4_pile": ("results/fig4_pile/construction.nc", "construction")}.items()
           if f in FIGURES}
if "fig4_history" in FIGURES:
    EXPORTS.update({f"fig4_history_{h}": (f"{FH}/piles/n{NH}/{h}_000.nc", h) for h in ("point", "rain")})


rule export_frames:
    input:
        lambda w: EXPORTS[w.figure][0],
        code=code_of("export_frames"),
    output:
        vtk=directory("results/{figure}/vtk"),
        animation=f"results/figures/{{figure}}.{ANIM_EXT}",
    wildcard_constraints:
        figure="|".join(EXPORTS) or "no_export",
    params:
        name=lambda w: EXPORTS[w.figure][1],
    log:
        "results/logs/{figure}/export.log",
    benchmark:
        "results/benchmarks/{figure}/export.tsv"
    conda:
        CONDA_ENV
    script:
        "../scripts/export_frames.py"


rule export:
    input:
        [f"results/figures/{f}.{ANIM_EXT}" for f in EXPORTS],
