"""The ahead-of-time module (mech.aot) against numba's just-in-time functions, and its build.

Both routes compile the same source: a run on either gives the same trajectory, to the
last bit, on scenes that reach every part of the kernel (3D and planar free bars, stick
and slip, a clamped blade with a rivet under a force, a pivot on a spring). The build
machinery is checked with a stand-in compiler: one build for concurrent callers, a
failure remembered and said, the JIT route taken then.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import sysconfig
import textwrap
import threading
from pathlib import Path

import numpy as np
import pytest

from mech import aot

ROOT = Path(__file__).resolve().parents[2]

RUN = textwrap.dedent("""
    import json, sys
    import numpy as np
    import mech.compiled
    from mech.scene import scene_from_dict
    from mech.solver import ImpactSolver
    steel = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
    scenes = [
        {"bar": dict(length=0.3, diameter=0.006, tip_radius=0.003, modes=4, **steel),
         "initial": dict(height=5e-4, angle_deg=30.0, velocity=[0.2, 0.1, -1.0]),
         "friction": dict(mu=0.5), "solver": dict(t_end=1.5e-3)},
        {"bar": dict(length=0.3, diameter=0.006, tip_radius=0.003, modes=6, **steel),
         "initial": dict(height=5e-4, angle_deg=30.0, velocity=[0.0, 0.0, -1.0]),
         "friction": dict(mu=0.3), "solver": dict(t_end=1.5e-3)},
        {"bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016,
                     modes={"axial": 1, "bending": 4}, modal_damping=0.05, **steel),
         "mount": dict(kind="clamp", position=0.02), "rivet": [dict(position=0.0015, offset=0.0, radius=0.0015)],
         "force": [dict(position=0.01, time=[0.0, 0.002], value=[0.0, 3.0])],
         "initial": dict(height=5e-5), "friction": dict(mu=0.3), "solver": dict(t_end=4e-3)},
        {"bar": dict(length=0.05, diameter=0.005, tip_radius=0.0025, modes=0, **steel),
         "mount": dict(kind="pivot", position=0.05, stiffness=1.0, preload_torque=0.01),
         "initial": dict(height=2e-5), "solver": dict(t_end=2e-3)},
    ]
    out = {"route": mech.compiled.ROUTE}
    for k, doc in enumerate(scenes):
        res = ImpactSolver(scene_from_dict(doc)).run()
        np.save(sys.argv[1] + f"/states{k}.npy", res.states)
        np.save(sys.argv[1] + f"/energy{k}.npy", np.column_stack(list(res.energy_columns.values())))
        out[k] = len(res.contact_columns["tip"])
    print(json.dumps(out))
""")


def _run(folder: Path, jit: bool) -> dict:
    folder.mkdir()
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env[aot.FORCE_JIT] = "1" if jit else "0"
    done = subprocess.run([sys.executable, "-c", RUN, str(folder)], env=env, capture_output=True, text=True,
                          timeout=1800)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_ahead_of_time_and_just_in_time_routes_give_the_same_trajectories(tmp_path):
    jit = _run(tmp_path / "jit", jit=True)
    ahead = _run(tmp_path / "aot", jit=False)
    assert jit["route"] == "jit" and ahead["route"] == "aot"
    assert all(jit[str(k)] > 0 for k in range(4))  # every scene has contacts
    for k in range(4):
        for what in ("states", "energy"):
            a = np.load(tmp_path / "jit" / f"{what}{k}.npy")
            b = np.load(tmp_path / "aot" / f"{what}{k}.npy")
            assert a.shape == b.shape
            np.testing.assert_array_equal(a, b, err_msg=f"scene {k}, {what}")


def test_an_argument_of_another_type_goes_to_the_jit_function_with_a_warning():
    import mech.compiled as compiled

    if compiled.ROUTE != "aot":
        pytest.skip("the ahead-of-time module is not in use here")
    coef = np.arange(15.0).reshape(5, 3)
    expected = np.empty(3)
    compiled.dense_eval(coef, 0.3, expected)
    got = np.empty(3)
    with pytest.warns(compiled.CompiledArgumentWarning, match="dense_eval argument 0") as caught:
        compiled.dense_eval(np.asfortranarray(coef), 0.3, got)  # read wrongly by the module
    np.testing.assert_array_equal(got, expected)
    # the warning names the line that called the entry point, not mech's own wrapper
    assert [w.filename for w in caught] == [__file__]
    closed_form = coef[0] + 0.3 * (coef[1] + 0.7 * (coef[2] + 0.3 * (coef[3] + 0.7 * coef[4])))
    np.testing.assert_allclose(expected, closed_form, rtol=1e-15)


def test_an_argument_passed_before_is_checked_again_where_it_is_wrong():
    """The checks skip an argument that is the very object the previous call passed at the
    same place (a segment's dense output at each circuit time); the same object at another
    place is checked there, and an argument that failed fails again."""
    import mech.aot as aot
    import mech.compiled as compiled

    if compiled.ROUTE != "aot":
        pytest.skip("the ahead-of-time module is not in use here")
    check = aot.argument_checks(aot.module_folder())["dense_eval"]
    coef, out = np.arange(15.0).reshape(5, 3), np.empty(3)
    check((coef, 0.3, out))
    check((coef, 0.3, out))  # the same objects: passed
    with pytest.raises(TypeError, match="dense_eval argument 0"):
        check((out, 0.3, out))  # out, passed at place 2, is 1-d: not a coefficient table
    fortran = np.asfortranarray(coef)
    for _ in range(2):
        with pytest.raises(TypeError, match="dense_eval argument 0"):
            check((fortran, 0.3, out))
    check((coef, 0.3, out))


def test_a_wrong_array_inside_a_tuple_argument_is_named_and_goes_to_the_jit_function():
    """The model and work tuples are checked element by element (once per tuple object):
    a float32 scratch array in the work tuple is named by its place, and the result is the
    same as with the right tuple."""
    import mech.compiled as compiled
    from mech.model import build_model
    from mech.scene import scene_from_dict

    if compiled.ROUTE != "aot":
        pytest.skip("the ahead-of-time module is not in use here")
    model = build_model(scene_from_dict({"bar": {"length": 0.1, "diameter": 0.006, "tip_radius": 0.003,
                                                 "modes": 2}}))
    y = model.initial_state()
    work = compiled.make_work(model.n)
    expected = np.empty(5)
    compiled.energies(y, model.arrays, work, expected)
    bad = tuple(a.astype(np.float32) if k == 2 else a for k, a in enumerate(work))
    got = np.empty(5)
    with pytest.warns(compiled.CompiledArgumentWarning, match=r"energies argument 2\[2\]: .*float32") as caught:
        compiled.energies(y, model.arrays, bad, got)
    assert [w.filename for w in caught] == [__file__]
    np.testing.assert_array_equal(got, expected)
    assert expected[0] > 0.0  # the bar moves down at its initial speed: kinetic energy


def test_a_new_tuple_is_checked_where_its_items_are_new():
    """A tuple argument that is a new tuple of the items the last one held (a segment's model
    tuple: the same arrays and a new drive) is checked at its new items only, and a wrong
    new item is still named; the items it shares passed before."""
    import mech.compiled as compiled
    from mech.model import build_model
    from mech.scene import scene_from_dict

    if compiled.ROUTE != "aot":
        pytest.skip("the ahead-of-time module is not in use here")
    check = aot.argument_checks(aot.module_folder())["energies"]
    model = build_model(scene_from_dict({"bar": {"length": 0.1, "diameter": 0.006, "tip_radius": 0.003,
                                                 "modes": 2}}))
    y, out = model.initial_state(), np.empty(5)
    work = compiled.make_work(model.n)
    check((y, model.arrays, work, out, None))
    fresh = model.kernel_arrays(model.arrays[-1].copy())
    check((y, fresh, work, out, None))  # a new drive: passed
    bad = model.kernel_arrays(model.arrays[-1].astype(np.float32))
    with pytest.raises(TypeError, match=r"energies argument 1\[14\]"):
        check((y, bad, work, out, None))
    wrong_first = (model.arrays[0].astype(np.float32),) + fresh[1:]
    with pytest.raises(TypeError, match=r"energies argument 1\[0\]"):
        check((y, wrong_first, work, out, None))


def test_the_drive_channels_take_the_ahead_of_time_route():
    """The drive (a float64 row per named channel) and the model's contact-drive index
    array (int64, one row per contact point) are arguments the module was built for (the
    warm-up sets every channel): a free bar driven with the input-work quadrature and a
    held blade, every channel given and a repulsion ramped, through the dense output, the
    contact series, the restore and the energy table, call no just-in-time function."""
    import warnings

    import mech.compiled as compiled
    from mech.scene import scene_from_dict
    from mech.solver import ImpactSolver

    if compiled.ROUTE != "aot":
        pytest.skip("the ahead-of-time module is not in use here")
    kinds = json.loads((aot.module_folder() / aot.SIGNATURES).read_text())
    model = kinds["dynamics"][2]
    assert model[0] == "tuple"
    assert model[1][-2:] == [["array", "int64", 2, "C"], ["array", "float64", 2, "C"]]  # cdrive, drive
    # the armature's arrays are an argument of their own: None (no armature), or its
    # parameters, gain table and contact states in the "_armature" export
    assert kinds["dynamics"][-1] == ["scalar", "none"]
    assert kinds["dynamics_armature"][-1] == ["tuple", [["array", "float64", 1, "C"], ["array", "float64", 2, "C"],
                                                        ["array", "float64", 1, "C"]]]
    steel = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
    free = {"bar": dict(length=0.1, diameter=0.006, tip_radius=0.003, modes=2, **steel),
            "initial": dict(height=1e-4, angle_deg=30.0, velocity=[0.3, 0.1, -1.0]),
            "friction": dict(mu=0.5), "solver": dict(t_end=1e-3)}
    blade = {"bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016,
                         modes={"axial": 1, "bending": 3}, modal_damping=0.05, **steel),
             "mount": dict(kind="clamp", position=0.02), "rivet": [dict(position=0.0015, offset=0.0, radius=0.0015)],
             "force": [dict(position=0.01, time=[0.0, 0.001], value=[0.0, 3.0])],
             "initial": dict(height=2e-5), "friction": dict(mu=0.3), "solver": dict(t_end=2e-3)}
    with warnings.catch_warnings():
        warnings.simplefilter("error", compiled.CompiledArgumentWarning)
        for doc, input_work in ((free, True), (blade, False)):
            solver = ImpactSolver(scene_from_dict(doc), keep_dense=True, input_work=input_work)
            t_end = doc["solver"]["t_end"]
            drives = {name: (0.0, 0.2) if name.startswith("repulsion.") else (0.4, 0.2) for name in solver.drive_names}
            seg = solver.advance(0.5 * t_end, drives)
            cp = solver.checkpoint()
            t = 0.5 * (seg.t_start + seg.t_end)
            seg.tip_forces(t)
            seg.contact(t)
            solver.advance(t_end, mu=0.3)
            solver.restore(cp)
            solver.advance(t_end, mu=0.3)
            solver.contact_series(np.linspace(0.0, t_end, 7))
            result = solver.result()
            assert len(result.contacts) >= 1
            assert np.isfinite(result.energy_table.residual.to_numpy()).all()
        # the armature: alone (a bar-less model) and through its card on the blade
        arm = dict(kind="plunger", mass=0.005, travel=2e-4, stop_stiffness=1e9, stop_damping=300.0,
                   spring_preload=0.1, force_gain=dict(position=[0.0, 1e-4, 2e-4], gain=[1.0, 1.2, 2.0]))
        card = dict(arm, card_position=0.01, card_lever=1.0, card_stiffness=1e5, card_damping=0.5)
        for doc in ({"armature": arm, "solver": dict(t_end=2e-3)},
                    dict(blade, armature=card, force=[], initial=dict(height=1e-4))):
            solver = ImpactSolver(scene_from_dict(doc), keep_dense=True)
            seg = solver.advance(1e-3, {"armature.force": (0.0, 3.0)})
            seg.armature(0.5e-3)
            solver.armature_now()
            solver.advance(2e-3)
            result = solver.result()
            assert result.armature["first_arrival"] is not None
            assert np.isfinite(result.history_columns["armature_position"]).all()


def _fake_build(calls, delay=0.2):
    def build(folder: Path):
        calls.append(folder)
        threading.Event().wait(delay)
        staging = folder.with_name(folder.name + ".tmp")
        staging.mkdir()
        aot.module_file(staging).write_bytes(b"")
        os.rename(staging, folder)
        return None
    return build


def test_concurrent_callers_build_once(tmp_path, monkeypatch):
    calls = []
    monkeypatch.setattr(aot, "_build", _fake_build(calls))
    folder = tmp_path / "aot-key"
    results = []
    threads = [threading.Thread(target=lambda: results.append(aot._build_locked(folder))) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results == [None] * 4 and len(calls) == 1
    assert aot.module_file(folder).is_file()


def test_a_failed_build_is_remembered_said_once_and_the_jit_route_taken(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv(aot.FORCE_JIT, raising=False)
    # (the sysconfig the build imports when it starts: mech.aot's own import of it is inside _build)
    monkeypatch.setattr(sysconfig, "get_config_var", lambda name: "no-such-compiler-here" if name == "CC" else None)
    assert aot.load() is None
    err = capsys.readouterr().err
    assert err.count("switchsim:") == 1 and "no C compiler" in err and "just-in-time" in err
    failed = list(tmp_path.glob("aot-*.failed"))
    assert len(failed) == 1
    # the next process does not try again; it says why, and how to retry
    assert aot.load() is None
    err = capsys.readouterr().err
    assert "failed before" in err and str(failed[0]) in err


def test_the_environment_forces_the_jit_route(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv(aot.FORCE_JIT, "1")
    assert aot.load() is None
    assert not list(tmp_path.iterdir())  # nothing built, nothing written


STALE = textwrap.dedent("""
    import json, sysconfig
    # no compiler here: a build is attempted only if no current module is found, and fails
    # (set before mech is imported: importing it loads the compiled module)
    sysconfig.get_config_var = lambda name: "no-such-compiler-here" if name == "CC" else None
    from mech import aot
    print(json.dumps([aot.load() is not None, aot.build_key(), aot.__file__]))
""")


def test_a_build_of_other_sources_is_never_loaded(tmp_path):
    """A copy of mech with this tree's build in its cache loads it; the same copy with one
    kernel line changed does not (its key differs), and builds instead (here: fails, JIT)."""
    import shutil

    import mech.compiled

    if mech.compiled.ROUTE != "aot":
        pytest.skip("the ahead-of-time module is not in use here")
    pkg = tmp_path / "tree" / "mech"
    pkg.mkdir(parents=True)
    for path in (ROOT / "mech").glob("*.py"):
        shutil.copy(path, pkg / path.name)
    cache = tmp_path / "cache"
    cache.mkdir()
    shutil.copytree(aot.module_folder(), cache / aot.module_folder().name)
    env = dict(os.environ, PYTHONPATH=str(tmp_path / "tree"), NUMBA_CACHE_DIR=str(cache))
    env.pop(aot.FORCE_JIT, None)

    def load():
        done = subprocess.run([sys.executable, "-c", STALE], env=env, capture_output=True, text=True, timeout=600,
                              cwd=str(tmp_path))
        assert done.returncode == 0, done.stderr[-3000:]
        return json.loads(done.stdout.strip().splitlines()[-1]), done.stderr

    (loaded, key, where), err = load()
    assert where == str(pkg / "aot.py")  # the copy, not this tree
    assert loaded and key == aot.build_key() and "switchsim:" not in err
    kernel = pkg / "kernel.py"
    kernel.write_text(kernel.read_text().replace("\n", "\nSTALE_MARK = 1  # a change of the kernel's source\n", 1))
    (loaded, stale_key, _), err = load()
    assert not loaded and stale_key != key
    assert "no C compiler" in err and "just-in-time" in err
    assert (cache / f"aot-{stale_key}.failed").is_file() and (cache / f"aot-{key}").is_dir()
