"""A notebook user's way in: :func:`geardyn.open_results` (every output of a build in one lazy DataTree), the
``ds.geardyn`` accessor (labels, impact classes and bifurcation kinds by name, shares, the workflow's figure of
each kind of file, provenance), ``ds.cf`` on every output and ``geardyn show``, on a small build
(tests/_results_build.py)."""

import os
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

import _results_build
import _workflow as wf
import geardyn
from geardyn import cli
from geardyn.solve.bifurcations import decode


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> Path:
    return wf.shared(tmp_path_factory, "results_build", _results_build.build) / "results"


def _files(results: Path) -> list[Path]:
    """The build's netCDF outputs, found by walking the directory (not by the code under test)."""
    return sorted(
        Path(d) / f for d, _, names in os.walk(results) for f in names if f.endswith(".nc") and "chunk_" not in f
    )


def _open_nc_handles() -> int:
    return sum(os.path.realpath(f"/proc/self/fd/{fd}").endswith(".nc") for fd in os.listdir("/proc/self/fd"))


def test_the_tree_holds_every_file_of_the_build_and_reads_no_value(results):
    files = _files(results)
    assert len(files) == len(_results_build.TARGETS) == 8
    before = _open_nc_handles()
    tree = geardyn.open_results(results)
    leaves = {node.path.lstrip("/") for node in tree.subtree if node.has_data}
    assert leaves == {str(p.relative_to(results).with_suffix("")) for p in files}
    assert set(tree.children) == set(_results_build.DESIGNS)
    assert set(tree["li2013"].children) == {"sweeps", "maps", "points", "response", "probabilities", "data"}
    assert _open_nc_handles() == before  # no file is held open
    for node in tree.subtree:
        for name, var in node.dataset.data_vars.items():
            assert not var.variable._in_memory, f"{node.path}/{name} was read"
    # a value is read when used, and it is the file's
    node = tree["li2013/maps/map_small"]
    with xr.open_dataset(results / "li2013/maps/map_small.nc") as ds:
        np.testing.assert_array_equal(node["label"].values, ds["label"].values)
        assert (
            node.attrs["git_commit"] == ds.attrs["git_commit"] and node.attrs["config_json"] == ds.attrs["config_json"]
        )
    with pytest.raises(FileNotFoundError, match="not a directory"):
        geardyn.open_results(results / "nowhere")


@pytest.mark.parametrize("rel", _results_build.TARGETS)
def test_names_agree_with_the_codes_through_the_flags(results, rel):
    with xr.open_dataset(results / rel) as ds:
        flagged = [n for n, v in ds.variables.items() if "flag_meanings" in v.attrs]
        assert ds.geardyn.flag_variables == flagged and flagged
        repr(ds.cf)
        for var in flagged:
            codes, meanings = ds[var].values, decode(ds[var].attrs)  # code -> meaning, as the writer wrote them
            assert set(ds[var].cf.flags.data_vars) == set(meanings.values())
            names = ds.geardyn.names(var).values
            shown = {code: names[codes == code] for code in np.unique(codes) if code in meanings}
            for code, found in shown.items():
                assert len(set(found)) == 1, (var, code)  # one name per code
                assert ds.geardyn.where(str(found[0]), var).values.sum() == (codes == code).sum()
            assert len({str(v[0]) for v in shown.values()}) == len(shown)  # and one code per name
        if "label" in ds:
            labels = ds.geardyn.labels.values
            assert set(labels[ds["label"].values == 1]) <= {"P1"} and set(labels[ds["label"].values == -3]) <= {"QP"}
            np.testing.assert_array_equal(ds.geardyn.where("quasi_periodic").values, ds["label"].values == -3)
            shares = ds.geardyn.shares()
            np.testing.assert_allclose(shares.sum(axis=1), 1.0)
            assert shares.values.min() >= 0.0
        if "impact_class" in ds:
            np.testing.assert_array_equal(
                ds.geardyn.where("double_sided").values, ds["impact_class"].values == 2
            )  # IMPACT_CLASSES: double_sided = 2
        with pytest.raises(KeyError, match="allowed"):
            ds.geardyn.where("P99")


@pytest.mark.parametrize("rel", _results_build.TARGETS)
def test_plot_draws_the_workflows_figure_of_every_kind(results, rel):
    with xr.open_dataset(results / rel) as ds:
        fig = ds.geardyn.plot()
        assert isinstance(fig, Figure) and fig.axes
        prov = ds.geardyn.provenance
        assert prov["design"] == rel.split("/")[0] and prov["git_commit"] == ds.attrs["git_commit"]
        assert prov["versions"]["numpy_version"] == ds.attrs["numpy_version"] and prov["config"]["design"]
        lines = ds.geardyn.describe()
        assert len(lines) < 20 and lines[0].startswith(ds.geardyn.kind)


def test_plot_options_a_sub_range_a_line_and_a_panel(results):
    with xr.open_dataset(results / "li2013/maps/map_small.nc") as ds:
        whole = ds.geardyn.plot()
        part = ds.geardyn.plot(range=(0.5, 1.0))
        assert whole.axes[0].get_xlim() != part.axes[0].get_xlim()
        assert max(part.axes[0].get_xlim()) <= 1.0 + 0.1  # the pixels' half-widths beyond the last centre
        one = ds.geardyn.plot(panel=0)
        assert len([a for a in one.axes if not hasattr(a, "_colorbar")]) == 1
        with pytest.raises(ValueError, match="panel = 9: out of range"):
            ds.geardyn.plot(panel=9)
        with pytest.raises(ValueError, match="no lines"):
            ds.geardyn.plot(line="base")
    with xr.open_dataset(results / "li2013/points/points_small.nc") as ds:
        assert len(ds.geardyn.plot(line="x1=0.5").axes) == 3  # one case: trajectory, Poincare map, spectrum
        with pytest.raises(ValueError, match="has no axis"):
            ds.geardyn.plot(range=(0.0, 1.0))


def test_show_prints_every_kind_in_under_20_lines(results, capsys):
    for path in _files(results):
        assert cli.main(["show", str(path)]) == 0
        out = capsys.readouterr().out.splitlines()
        assert 3 <= len(out) < 20 and out[0].startswith(str(path)), out
        assert any("commit" in line for line in out)


def test_show_of_a_foreign_or_damaged_file_is_one_line(results, tmp_path, capsys):
    foreign = tmp_path / "foreign.nc"
    xr.Dataset({"t": ("x", np.arange(3.0))}).to_netcdf(foreign)
    damaged = tmp_path / "damaged.nc"
    data = (results / "li2013/maps/map_small.nc").read_bytes()
    damaged.write_bytes(data[: len(data) // 3])
    for path, why in ((foreign, "not a geardyn output"), (damaged, "cannot be read"), (tmp_path / "no.nc", "")):
        assert cli.main(["show", str(path)]) == 1
        captured = capsys.readouterr()
        assert captured.out == "" and len(captured.err.splitlines()) == 1 and why in captured.err


@pytest.fixture(scope="module")
def whole_pipeline(tmp_path_factory) -> Path:
    """The whole pipeline's small build (tests/test_pipeline_outputs.py builds the same, once per session)."""
    from test_pipeline_outputs import _small_pipeline  # noqa: PLC0415 - the other module's build, shared by name

    return wf.shared(tmp_path_factory, "pipeline", _small_pipeline) / "results"


def test_every_kind_of_the_whole_pipeline_opens_shows_and_draws(whole_pipeline, capsys):
    """Every netCDF kind the pipeline writes (a plus design's too): in the tree, ``ds.cf`` finds its flag
    variables, ``show`` prints it in under 20 lines, and ``plot()`` draws it or names the kinds it draws."""
    from geardyn.accessor import FIGURES  # noqa: PLC0415 - the table of kinds under test

    files = _files(whole_pipeline)
    tree = geardyn.open_results(whole_pipeline)
    assert sum(node.has_data for node in tree.subtree) == len(files) > 10
    drawn = set()
    for path in files:
        with xr.open_dataset(path) as ds:
            flagged = [n for n, v in ds.variables.items() if "flag_meanings" in v.attrs]
            assert [n for n in flagged if ds[n].cf.is_flag_variable] == flagged == ds.geardyn.flag_variables
            assert cli.main(["show", str(path)]) == 0 and len(capsys.readouterr().out.splitlines()) < 20
            if ds.geardyn.kind in FIGURES:
                assert isinstance(ds.geardyn.plot(), Figure), path
                drawn.add(ds.geardyn.kind)
            else:
                with pytest.raises(ValueError, match="no figure of its own"):
                    ds.geardyn.plot()
    assert {"sweep", "points", "closed_graph", "stiffness_table", "probabilities", "te", "modal"} <= drawn
