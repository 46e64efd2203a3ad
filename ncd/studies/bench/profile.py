"""Where the CPU of the figures' jobs goes: a sampled profile of a real run of the workflow.

``py-spy record --subprocesses --native --format raw`` samples every Python process of a
Snakemake run (the scheduler, each job's interpreter, each notebook's nbconvert and kernel)
``rate`` times a second and writes one line per distinct stack,
``process P:"cmdline";...;process C:"cmdline";frame;...;frame COUNT``, outermost first: the
chain of processes from the one py-spy started down to the sampled one, then the frames of
the sampled thread, leaf last.  Idle threads are not sampled, so samples / rate is about
the CPU time.

Each sample falls in one of four categories, read from the frames below its innermost
Python frame (the native code that Python frame is waiting on, its "tail"):

* ``kernel``: a numba-compiled function.  LLVM's JIT code (compiled, or loaded from numba's
  ``cache=True`` files) lives in anonymous memory, so py-spy shows it as ``0x... (?)``, with
  no library, right under the Python frame that called it (the dispatcher's own frames are
  lost in the unwinding); libm or NRT frames under it count as the kernel's.  A library
  py-spy has not yet mapped shows the same way: only such a frame under the project's own
  code is a kernel (:func:`classify`).
* ``solver``: an LP solver: HiGHS (highspy, scipy's ``_highspy``), Clarabel, CLP (cylp and
  the COIN-OR libraries), whatever they call.
* ``compiled``: other native code (numpy, scipy, BLAS, libc, numba's type dispatch, ...).
* ``python``: no native code but the interpreter's own (libpython): Python bytecode.

A sample is mapped to its Snakemake job through its process chain: a ``script:`` job runs
``python <workdir>/.snakemake/scripts/tmpXXXX.<script>.py`` and a ``notebook:`` job runs
``jupyter-nbconvert ... tmpXXXX.<notebook>.ipynb`` (whose kernel is its child), so the
innermost process naming such a wrapper is the job.  The job's figure is the folder of its
rule's benchmark file (as in :func:`ncd.studies.bench.runs.dag_table`), read from the rules
files: the rule comes from the wrapper (kept with ``--skip-script-cleanup``: its preamble
holds the pickled ``snakemake`` object), else from the script name when a single rule runs
that script.  Samples of processes that are no job (Snakemake itself) go to ``(snakemake)``.
"""
import ast
import json
import pickle
import re
import shutil
import subprocess
import sys
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

CATEGORIES = ("kernel", "solver", "compiled", "python")
GOAL = 0.8            # the share of a figure's CPU inside kernels and LP solvers set as the target
# Below this many samples a share is not judged: the standard error of a share from n
# independent samples is at most 0.5 / sqrt(n), 0.035 here, small beside the margins the
# goal is read with (and a sampling profiler's samples are not quite independent).
MIN_SAMPLES = 200
NOT_A_JOB = "(snakemake)"
PROJECT = ("ncd",)       # the packages whose code calls the kernels (besides the jobs' scripts)
HOT_SPOTS = 5

PROCESS = re.compile(r'process (\d+):"((?:[^"]|"(?!;|$))*)"(?:;|$)')
# a Python frame: a .py file, <frozen ...> or <string>, or a console script (``snakemake:8``)
PYTHON_FRAME = re.compile(r"\((?:(?:[^()]*\.pyw?|<[^<>]*>)(?::\d+)?|[^().:?]+:\d+)\)$")
JIT_FRAME = re.compile(r"^0x[0-9a-fA-F]+ \(\?\)$")
# libraries (or their Python packages' extension modules) of the LP solvers, and the C++ /
# Rust symbol prefixes of their code when it is built with debug information
SOLVER_MODULE = re.compile(r"highs|clarabel|cylp|libclp|libcoinutils|libosi|libcbc|libcgl", re.IGNORECASE)
SOLVER_SYMBOL = re.compile(r"^(?:Highs|HEkk|HFactor|HPresolve|HighsSimplex|Clp|Coin|Osi|clarabel::)")
INTERPRETER_MODULE = re.compile(r"\((?:libpython\d[\d.]*\.so[\d.]*|python\d?(?:\.\d+)?)\)$")
ROOT_MODULE = re.compile(r"\((?:libc\.so[\d.]*|libpthread\.so[\d.]*|ld-linux[^()]*)\)$")
WRAPPER = re.compile(r"(?P<path>\S*\.snakemake/scripts/tmp[A-Za-z0-9_]+\.(?P<script>[^/\s\"]+\.(?:py|ipynb)))")
NUMBA_LOAD = "_compile_for_args (numba/core/dispatcher.py"
IMPORT = "_find_and_load (<frozen importlib._bootstrap>"


@dataclass(frozen=True)
class Sample:
    """One line of py-spy's raw output: the process chain (pid, cmdline), outermost first,
    the frames of the sampled thread, leaf last, and how many samples had that stack."""
    processes: tuple
    frames: tuple
    count: int


def parse_raw(text):
    """The samples of py-spy's raw output ``text`` (a list of :class:`Sample`)."""
    out = []
    for k, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        stack, _, count = line.rpartition(" ")
        if not stack or not count.isdigit():
            raise ValueError(f"line {k} of the py-spy output is not 'frames COUNT': {line[:200]!r}")
        processes, pos = [], 0
        while (m := PROCESS.match(stack, pos)):
            processes.append((int(m.group(1)), m.group(2)))
            pos = m.end()
        frames = tuple(f for f in stack[pos:].split(";") if f)
        out.append(Sample(tuple(processes), frames, int(count)))
    return out


def frame_kind(frame):
    """``python``, ``jit`` (anonymous native code: numba's), ``solver``, ``interpreter``
    (libpython or the python executable) or ``native`` (any other library)."""
    if PYTHON_FRAME.search(frame):
        return "python"
    if JIT_FRAME.match(frame):
        return "jit"
    name, _, where = frame.partition(" (")
    if SOLVER_MODULE.search(where) or SOLVER_SYMBOL.match(name):
        return "solver"
    if INTERPRETER_MODULE.search(frame):
        return "interpreter"
    return "native"


def tail(frames):
    """The frames below the innermost Python frame (the native code it waits on).  A stack
    with no Python frame (a thread or process starting or ending) loses its root frames in
    libc and the loader first."""
    kinds = [frame_kind(f) for f in frames]
    if "python" in kinds:
        last = len(kinds) - 1 - kinds[::-1].index("python")
        return kinds[last + 1:]
    k = 0
    while k < len(frames) and kinds[k] == "native" and ROOT_MODULE.search(frames[k]):
        k += 1
    return kinds[k:]


def project_frame(frame, packages=PROJECT):
    """Whether a Python frame is the project's code: a module of ``packages`` (py-spy names a
    package's file from its package, ``ncd/solver/nlgs.py``) or a file of no package that is
    not the standard library's (a job's script, a notebook's cell); not a console script
    (``snakemake``, ``jupyter-nbconvert``)."""
    where = frame.rpartition(" (")[2].rstrip(")")
    path = re.sub(r":\d+$", "", where)
    if path.startswith("<") or not path.endswith((".py", ".pyw")):
        return False
    first = path.split("/")[0]
    if "/" in path:
        return first in packages
    return Path(first).stem not in sys.stdlib_module_names


def classify(frames, packages=PROJECT):
    """The category of a sample (:data:`CATEGORIES`): an LP solver anywhere in the tail, else
    numba JIT code in it under the project's own code, else any native code but the
    interpreter's, else Python.

    py-spy shows any address outside the libraries it knows as ``0x... (?)``, and re-reads
    the process's memory map after such a miss: the first sample in a library loaded since
    the last reading (an extension module being initialized by an import, a module's first
    call) looks like JIT code.  The project's kernels are called by the project's code
    (``packages``, a job's script), so an unknown address under a library's Python frame
    (importlib, subprocess, llvmlite, ...) counts as that library's compiled code.  A
    solver's library being initialized by an import is no solving either.  The project runs
    no kernel on a thread without Python frames (its threads are Python's), so an unknown
    address there is unknown code (``compiled``)."""
    kinds = set(tail(frames))
    inner = next((f for f in reversed(frames) if PYTHON_FRAME.search(f)), None)
    if "solver" in kinds:
        return "compiled" if inner is not None and "(<frozen importlib" in inner else "solver"
    if "jit" in kinds:
        return "kernel" if inner is not None and project_frame(inner, packages) else "compiled"
    if "native" in kinds:
        return "compiled"
    return "python"


def hot_function(frames):
    """The innermost Python frame without its line number (``name (file)``; a job's wrapper
    ``tmpXXXX.<script>.py`` named by its script), or ``(native)``."""
    for f in reversed(frames):
        if PYTHON_FRAME.search(f):
            return re.sub(r"\(tmp[A-Za-z0-9_]+\.(?=[^()]+\.(?:py|ipynb)\)$)", "(", re.sub(r":\d+\)$", ")", f))
    return "(native)"


# ------------------------------------------------------------------ jobs and figures
@dataclass(frozen=True)
class Rule:
    """A rule of a rules file: its figure (the folder of its benchmark file, ``{figure}``
    when that is a wildcard, else the rules file's name), its script or notebook (file
    name), and the rules file."""
    figure: str
    script: str
    source: str


def _directive(block, name):
    """The text of directive ``name:`` of a rule's block (same line, or the next one)."""
    m = re.search(rf"^\s+{name}:[ \t]*(\S.*)?$(?:\n\s+(\S.*)$)?", block, re.MULTILINE)
    if m is None:
        return None
    return (m.group(1) or m.group(2) or "").strip()


def _bench_folder(text, names):
    """The folder of a benchmark path written ``bench(NAME, "...")``, ``bench("folder", ...)``
    or ``"results/benchmarks/<folder>/..."``; ``index`` for a file directly under
    results/benchmarks (as :func:`ncd.studies.bench.runs.dag_table` names it)."""
    if text is None:
        return None
    if m := re.match(r'bench\(\s*(?:"([^"]+)"|(\w+))', text):
        return m.group(1) or names.get(m.group(2))
    if m := re.match(r'"results/benchmarks/([^"]+)"', text):
        parts = m.group(1).split("/")
        return parts[0] if len(parts) > 1 else "index"
    return None


def rules_table(rules_dir):
    """Every rule with a ``script:`` or ``notebook:`` of the rules files ``rules_dir/*.smk``:
    ``{rule: Rule}``.  Nothing is listed by hand: a new rules file or rule is found here."""
    table = {}
    for path in sorted(Path(rules_dir).glob("*.smk")):
        text = path.read_text()
        names = dict(re.findall(r'^([A-Z][A-Z0-9_]*)\s*=\s*"([^"]*)"', text, re.MULTILINE))
        heads = list(re.finditer(r"^(?:rule|checkpoint)\s+(\w+)\s*:", text, re.MULTILINE))
        for k, head in enumerate(heads):
            block = text[head.end():heads[k + 1].start() if k + 1 < len(heads) else len(text)]
            run = _directive(block, "script") or _directive(block, "notebook")
            if not run or not (m := re.match(r'["\']([^"\']+)["\']', run)):
                continue
            figure = _bench_folder(_directive(block, "benchmark"), names) or path.stem
            table[head.group(1)] = Rule(figure, Path(m.group(1)).name, path.name)
    return table


def job_wrapper(processes):
    """``(script, wrapper path)`` of the innermost process of the chain that runs a Snakemake
    job's wrapper (``.snakemake/scripts/tmpXXXX.<script>.py|.ipynb`` on its command line), or
    None when no process of the chain is a job."""
    for _, cmdline in reversed(processes):
        if m := WRAPPER.search(cmdline):
            return m.group("script"), m.group("path")
    return None


def read_wrapper(path):
    """``(rule, wildcards)`` of a job from its wrapper script or notebook (the preamble
    Snakemake writes: ``snakemake = pickle.loads(b'...')``, the bytes' repr in either quotes),
    or None when the file is gone
    (Snakemake deletes them unless run with ``--skip-script-cleanup``)."""
    path = Path(path)
    if not path.exists():
        return None
    text = path.read_text()
    if path.suffix == ".ipynb":
        text = "\n".join("".join(c.get("source", "")) for c in json.loads(text)["cells"])
    m = re.search(r"""pickle\.loads\((b(?:'(?:[^'\\]|\\.)*'|"(?:[^"\\]|\\.)*"))\)""", text)
    if m is None:
        raise ValueError(f"{path}: no Snakemake preamble (pickle.loads(b'...')) found")
    smk = pickle.loads(ast.literal_eval(m.group(1)))  # noqa: S301 (this run's own wrapper)
    wildcards = getattr(smk, "wildcards", None)
    return str(smk.rule), {str(k): str(v) for k, v in (wildcards.items() if wildcards is not None else ())}


def figure_of(script, table, rule=None, wildcards=None, rules_dir="workflow/rules"):
    """The figure of a job running ``script`` (a wrapper's file name, e.g. ``fig1_explore.py``).

    With the job's ``rule`` (from its wrapper) that rule's figure; without it, the figure
    of the rules running that script, when they all have the same one.  A script no rule
    runs, a rule of no rules file, or a script run by rules of several figures without its
    rule, is an error naming it: the profile would otherwise file its CPU under a wrong
    figure.  A ``{figure}`` folder (rules shared by the figures, e.g. ``render_html``) is
    the job's ``figure`` wildcard."""
    wildcards = wildcards or {}
    if rule is not None:
        if rule not in table:
            raise ValueError(f"rule {rule!r} (job script {script!r}) is in no rules file of {rules_dir}")
        if table[rule].script != script:
            raise ValueError(f"rule {rule!r} runs {table[rule].script!r} in {table[rule].source}, "
                             f"not the job's script {script!r}")
        figures = {table[rule].figure}
    else:
        figures = {r.figure for r in table.values() if r.script == script}
        if not figures:
            raise ValueError(f"script {script!r} of a job is run by no rule of {rules_dir} "
                             "(script: or notebook: directives)")
        if len(figures) > 1:
            raise ValueError(f"script {script!r} is run by rules of several figures ({', '.join(sorted(figures))}): "
                             "the job's rule is needed (run Snakemake with --skip-script-cleanup)")
    figure = figures.pop()
    if figure == "{figure}":
        if "figure" not in wildcards:
            raise ValueError(f"script {script!r}: its rule's benchmark folder is the wildcard {{figure}}, "
                             "and the job's wildcards are unknown")
        figure = wildcards["figure"]
    return figure


def sample_figures(samples, table, rules_dir="workflow/rules"):
    """The figure of each sample (:func:`figure_of`; :data:`NOT_A_JOB` for Snakemake's own
    processes), each wrapper read once."""
    cache, out = {}, []
    for s in samples:
        job = job_wrapper(s.processes)
        if job is None:
            out.append(NOT_A_JOB)
            continue
        if job not in cache:
            script, path = job
            found = read_wrapper(path)
            rule, wildcards = found if found is not None else (None, None)
            cache[job] = figure_of(script, table, rule, wildcards, rules_dir)
        out.append(cache[job])
    return out


# ------------------------------------------------------------------ the profile
def profile_table(samples, figures, rate, order=()):
    """The profile per figure, a Dataset over ``figure``: samples, the share of each
    category, the sampled CPU seconds (samples / rate), the shares of numba's dispatch and
    cache loading and of imports (diagnostics, across categories), and the
    :data:`HOT_SPOTS` innermost Python functions of the samples outside kernels and solvers
    with their shares.  Figures in ``order`` first, then the others, :data:`NOT_A_JOB` last."""
    counts = defaultdict(Counter)
    loads, imports = Counter(), Counter()
    hot = defaultdict(Counter)
    for s, fig in zip(samples, figures):
        cat = classify(s.frames)
        counts[fig][cat] += s.count
        joined = ";".join(s.frames)
        loads[fig] += s.count * (NUMBA_LOAD in joined)
        imports[fig] += s.count * (IMPORT in joined)
        if cat in ("compiled", "python"):
            hot[fig][hot_function(s.frames)] += s.count
    labels = [f for f in order if f in counts] + sorted(f for f in counts if f not in order and f != NOT_A_JOB)
    labels += [NOT_A_JOB] if NOT_A_JOB in counts else []
    n = np.array([sum(counts[f].values()) for f in labels], np.int64)
    share = lambda c: np.array([counts[f][c] for f in labels], float) / np.maximum(n, 1)   # noqa: E731
    top = [hot[f].most_common(HOT_SPOTS) + [("", 0)] * (HOT_SPOTS - len(hot[f].most_common(HOT_SPOTS)))
           for f in labels]
    ds = xr.Dataset(
        {"samples": ("figure", n, {"units": "1", "long_name": "samples of the figure's jobs"}),
         **{f"{c}_share": ("figure", share(c), {"units": "1", "long_name": text}) for c, text in (
             ("kernel", "share of the samples inside numba-compiled kernels"),
             ("solver", "share of the samples inside LP solvers (HiGHS, Clarabel, CLP)"),
             ("compiled", "share of the samples in other compiled code (numpy, scipy, BLAS, libc, ...)"),
             ("python", "share of the samples in the Python interpreter"))},
         "sampled_cpu_s": ("figure", n / float(rate), {"units": "s", "long_name": "CPU seconds sampled: samples / rate"}),
         "numba_load_share": ("figure", np.array([loads[f] for f in labels], float) / np.maximum(n, 1),
                              {"units": "1", "long_name": "share of the samples in numba's dispatch: typing, "
                               "compiling or loading kernels from the cache"}),
         "import_share": ("figure", np.array([imports[f] for f in labels], float) / np.maximum(n, 1),
                          {"units": "1", "long_name": "share of the samples importing modules"}),
         "hot_function": (("figure", "rank"), np.array([[h for h, _ in t] for t in top], dtype=object).astype(str),
                          {"long_name": "innermost Python function of the samples outside kernels and solvers"}),
         "hot_share": (("figure", "rank"), np.array([[c for _, c in t] for t in top], float) / np.maximum(n, 1)[:, None],
                       {"units": "1", "long_name": "share of the figure's samples in that function, outside kernels "
                        "and solvers"})},
        coords={"figure": np.array(labels, dtype=str), "rank": np.arange(1, HOT_SPOTS + 1)})
    ds["rank"].attrs.update(units="1", long_name="rank of the hot spot")
    ds["figure"].attrs.update(long_name="figure (folder of the job's benchmark file); (snakemake): the scheduler")
    ds.attrs.update(rate=float(rate), goal=GOAL, min_samples=MIN_SAMPLES, samples=int(n.sum()))
    return ds


def goal_status(ds):
    """Per figure of a :func:`profile_table` Dataset: ``met`` when kernels and solvers hold
    at least :data:`GOAL` of its samples, ``not met`` below, ``too few samples`` under
    :data:`MIN_SAMPLES`; the scheduler's row (:data:`NOT_A_JOB`) is no job: ``—``."""
    inside = (ds.kernel_share + ds.solver_share).values
    goal = float(ds.attrs.get("goal", GOAL))
    least = int(ds.attrs.get("min_samples", MIN_SAMPLES))
    return ["—" if f == NOT_A_JOB else "too few samples" if n < least else "met" if x >= goal else "not met"
            for f, n, x in zip(ds.figure.values, ds.samples.values, inside)]


def job_wall(bench_files):
    """Wall seconds of every figure's jobs from their benchmark files
    ``results/benchmarks/<figure>/<rule>.tsv`` (``index`` for a file directly under
    ``results/benchmarks``): ``{figure: seconds}``."""
    out = Counter()
    for p in map(Path, bench_files):
        lines = p.read_text().splitlines()
        rec = dict(zip(lines[0].split("\t"), lines[1].split("\t")))
        out[p.parent.name if p.parent.name != "benchmarks" else "index"] += float(rec["s"])
    return dict(out)


# ------------------------------------------------------------------ recording
def py_spy():
    """The py-spy executable (the ``bench`` extra), or a clear error."""
    exe = shutil.which("py-spy")
    if exe is None:
        raise RuntimeError("py-spy is not installed: pip install -e '.[bench]' (it samples the jobs' stacks)")
    return exe


def py_spy_version():
    """py-spy's version (``py-spy --version``: ``py-spy 0.4.3``)."""
    out = subprocess.run([py_spy(), "--version"], capture_output=True, text=True, check=True).stdout
    return out.split()[-1] if out.split() else "unknown"


def record(command, output, rate, cwd=None, env=None):
    """Run ``command`` under ``py-spy record --subprocesses --native --format raw``, sampling
    ``rate`` times a second into ``output``; returns ``(py-spy's command line, its printout)``.
    A failure of the command, or of py-spy (no permission to trace: ptrace), is an error
    with the end of the printout."""
    cmd = [py_spy(), "record", "--subprocesses", "--native", "--format", "raw", "--rate", str(int(rate)),
           "--output", str(output), "--", *map(str, command)]
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    printout = proc.stdout + proc.stderr
    if proc.returncode != 0 or not Path(output).exists():
        raise RuntimeError(f"py-spy record failed (exit {proc.returncode}): {' '.join(cmd)}\n{printout[-6000:]}")
    return cmd, printout


def recording_counts(printout):
    """``(samples, errors)`` of py-spy's closing line ``Samples: N Errors: M`` (errors: stacks
    it could not read, lost to every category)."""
    m = re.search(r"Samples:\s*(\d+)\s+Errors:\s*(\d+)", printout)
    if m is None:
        raise ValueError(f"no 'Samples: N Errors: M' line in py-spy's printout: {printout[-500:]!r}")
    return int(m.group(1)), int(m.group(2))


def capped(config, overlay):
    """``config`` with ``overlay``'s values, where a number of the overlay is a cap
    (the smaller of the two is kept): ``config/quick.yaml`` lowers realization counts, and
    over a configuration already smaller (a test's reduced one) it must not raise them."""
    if not isinstance(overlay, dict):
        both_numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (config, overlay))
        return min(config, overlay) if both_numbers else overlay
    out = dict(config) if isinstance(config, dict) else {}
    for k, v in overlay.items():
        out[k] = capped(out[k], v) if k in out else v
    return out
