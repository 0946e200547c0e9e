# SPDX-License-Identifier: BSD-2-Clause
"""The Python binding of the C API (pkm4puu.capi) against pkm.h and the FMUs:

- every struct field and every function of the header (parsed here on its
  own, with C's layout rules) is in the binding, at the same offset;
- the library's parameters are the FMUs' parameters (their committed model
  descriptions: names, value references, starts, ranges, units,
  descriptions), but the plant's initial state, which pkm_init_pose takes;
  their defaults are docs/model.md's (spec.py);
- every parameter is reachable from Python: a solver setting set through
  Plant.set_solver acts (max_jacobian_condition refuses the home pose), and
  an unknown keyword raises TypeError naming it and the known ones;
- a failing batch call's PkmError names its C function and the first sample
  not computed; capi.load loads a file once.
"""
import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from pkm4puu import capi, spec

from conftest import REPO

# C's sizes and alignments on the 64-bit platforms the project builds for.
C_TYPES = {"double": 8, "int": 4, "unsigned": 4, "size_t": 8, "const char*": 8}


def header_structs(text):
    """{struct: ([(field, offset, size)], sizeof)} of pkm.h's typedef'd
    structs, laid out by C's rules (each field at its alignment, the struct
    padded to its largest)."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    out = {}
    for body, name in re.findall(r"typedef\s+struct\s*\{(.*?)\}\s*(\w+)\s*;", text, flags=re.S):
        fields, offset, align_max = [], 0, 1
        for decl in filter(None, (d.strip() for d in body.split(";"))):
            m = re.fullmatch(r"((?:const\s+)?\w+\s*\*?)\s*(.*)", decl, flags=re.S)
            ctype = re.sub(r"\s+", " ", m.group(1)).replace(" *", "*").strip()
            size = C_TYPES[ctype]
            for item in m.group(2).split(","):
                f = re.fullmatch(r"\s*(\w+)\s*(?:\[(\d+)\])?\s*", item)
                offset = (offset + size - 1) // size * size
                fields.append((f.group(1), offset, size * int(f.group(2) or 1)))
                offset += size * int(f.group(2) or 1)
                align_max = max(align_max, size)
        out[name] = (fields, (offset + align_max - 1) // align_max * align_max)
    return out


@pytest.fixture(scope="module")
def lib(pkm_library):
    return capi.load(pkm_library)


def test_every_struct_field_of_pkm_h_is_in_the_binding(lib, pkm_header):
    structs = header_structs(pkm_header.read_text())
    assert {"pkm_parameter", "pkm_outputs", "pkm_state", "pkm_inverse_result"} <= set(structs), structs.keys()
    for name, (fields, size) in structs.items():
        ours = [(f, ft.offset, lib.ffi.sizeof(ft.type)) for f, ft in lib.ffi.typeof(name).fields]
        assert ours == fields, f"{name}: binding {ours} != pkm.h {fields}"
        assert lib.ffi.sizeof(name) == size, name


def test_every_function_of_pkm_h_is_in_the_binding(lib, pkm_header):
    names = re.findall(r"PKM_API\s+[\w\s\*]*?\b(pkm_\w+)\s*\(", pkm_header.read_text())
    assert len(names) >= 25, names
    missing = [n for n in names if not hasattr(lib.c, n)]
    assert not missing, missing


def fmu_parameters(model):
    """{name: attributes} of the parameters in a committed FMI 2.0 model description."""
    root = ET.parse(REPO / "src" / "models" / model / "fmi2" / "modelDescription.xml").getroot()
    out = {}
    for v in root.iter("ScalarVariable"):
        if v.get("causality") != "parameter":
            continue
        t = v[0]
        out[v.get("name")] = {"vr": int(v.get("valueReference")), "description": v.get("description"),
                              "variability": v.get("variability"), "integer": t.tag == "Integer",
                              "unit": t.get("unit", ""), "start": float(t.get("start")),
                              "min": float(t.get("min", "-inf")), "max": float(t.get("max", "inf"))}
    return out


def test_the_librarys_parameters_are_the_fmus(lib):
    plant, inverse = fmu_parameters("PKM4PUU"), fmu_parameters("PKM4PUU_Inverse")
    initial_state = {"x0", "y0", "z0", "phi0", "dx0", "dy0", "dz0", "dphi0"}
    assert set(lib.parameters) == (set(plant) | set(inverse)) - initial_state
    for name, p in lib.parameters.items():
        fmu = plant.get(name) or inverse[name]
        assert p.fmus == (name in plant) + 2 * (name in inverse), name
        assert (p.value_reference, p.description, p.unit, bool(p.is_integer)) == \
            (fmu["vr"], fmu["description"], fmu["unit"], fmu["integer"]), name
        assert (p.start, p.min, p.max) == (fmu["start"], fmu["min"], fmu["max"]), name
        assert bool(p.is_tunable) == (fmu["variability"] == "tunable"), name


def test_the_librarys_defaults_are_the_spec(lib):
    for name, value in {**spec.PARAMETER_DEFAULTS, **spec.SOLVER_DEFAULTS}.items():
        assert math.isclose(lib.parameters[name].start, value, rel_tol=1e-15, abs_tol=1e-300), name


def test_every_parameter_is_reachable_and_read_back(lib):
    """Each parameter set to a value of its range other than its default
    (alone: the set must stay consistent) reads back exactly."""
    for name, p in lib.parameters.items():
        hi = p.max if math.isfinite(p.max) else 10 * p.start
        value = p.min if p.start != p.min else hi
        if name == "rho_max":
            value = 0.5  # above rho_min
        if name == "rho_min":
            value = -0.5
        if name.startswith("I_rod"):
            value = p.start * 1.01  # the rod's triangle inequalities
        if name == "solver":
            value = lib.c.PKM_SOLVER_ROSENBROCK
        with capi.Plant(lib, **{name: value}) as m:
            assert m.get(name) == value, name


def test_set_solver_sets_the_guards(lib):
    """max_jacobian_condition through Plant.set_solver acts: no pose has a
    condition number below 1.0000001, so the home pose is refused."""
    with capi.Plant(lib) as m:
        m.init_pose(0.0, spec.P0)
        m.set_solver(max_jacobian_condition=1.0000001)
        assert m.get("max_jacobian_condition") == 1.0000001
        with pytest.raises(capi.PkmError, match="max_jacobian_condition") as e:
            m.init_pose(0.0, spec.P0)
        assert e.value.status == lib.c.PKM_ERR_SINGULAR


def test_unknown_keywords_raise_naming_the_known_ones(lib):
    with pytest.raises(TypeError, match=r"unknown parameter 'payload_mas'; the known ones: h, l, .*payload_mass"):
        capi.Plant(lib, payload_mas=0.25)
    with capi.Plant(lib) as m:
        with pytest.raises(TypeError, match=r"'max_jacobian_conditon'; the known ones: solver, rk4_step"):
            m.set_solver(max_jacobian_conditon=10.0)
        with pytest.raises(TypeError, match=r"unknown parameter 'g'"):
            m.set_solver(g=0.0)  # a parameter, not a solver setting: Plant.set
        with pytest.raises(TypeError, match=r"beta has 4 values"):
            m.set(beta=0.1)
        assert m.get("g") == spec.G, "a refused call changes nothing"


def test_a_failing_batch_call_names_its_function_and_sample(lib):
    """A non-finite sample stops pkm_regressor_poses / _joints there: the
    error starts with the C function's name and `sample` is that sample."""
    zero = np.zeros((3, 4))
    with capi.Plant(lib) as m:
        poses = np.tile(spec.P0, (3, 1))
        _, _, rho, _ = m.regressor_poses(poses, zero, zero)
        poses[1, 2] = rho[2, 0] = math.nan
        with pytest.raises(capi.PkmError, match=r"^pkm_regressor_poses: status ") as e:
            m.regressor_poses(poses, zero, zero)
        assert e.value.sample == 1 and e.value.status == lib.c.PKM_ERR_NONFINITE
        with pytest.raises(capi.PkmError, match=r"^pkm_regressor_joints: status ") as e:
            m.regressor_joints(rho, zero, zero)
        assert e.value.sample == 2 and e.value.status == lib.c.PKM_ERR_NONFINITE


def test_a_library_is_loaded_once_per_file(pkm_library, lib):
    """capi.load returns the same Library for the same file however it is
    named (the planner loads it for every model it makes)."""
    assert capi.load(str(pkm_library)) is lib
    assert capi.load(pkm_library.parent / ".." / pkm_library.parent.name / pkm_library.name) is lib
