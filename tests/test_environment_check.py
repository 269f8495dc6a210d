"""check_environment: versions printed, warnings with a fix when something will break."""

import json
import re
import sys
from pathlib import Path

import pytest

import coursekit as ck
from coursekit import environment_check as envc


def _fake_versions(monkeypatch, **override):
    real = envc._installed_version

    def fake(dist):
        return override[dist] if dist in override else real(dist)
    monkeypatch.setattr(envc, "_installed_version", fake)


def test_prints_python_and_package_versions(capsys):
    report = ck.check_environment()
    out = capsys.readouterr().out
    assert f"Python {sys.version_info.major}.{sys.version_info.minor}" in out
    for name in ("numpy", "scipy", "sympy", "matplotlib", "ipywidgets", "coursekit"):
        assert re.search(rf"{name}\s+\d", out), out
    assert isinstance(report, ck.EnvironmentReport)
    assert report.versions["coursekit"] == ck.__version__


def test_dev_environment_is_ok_and_finds_the_widget_frontend(capsys):
    report = ck.check_environment(show=False)
    assert capsys.readouterr().out == ""
    assert report.ok, report.warnings
    assert report.widget_frontend is not None and int(report.widget_frontend.split(".")[0]) >= 5
    assert "ok" in repr(report)


@pytest.mark.parametrize("name, old", [("numpy", "1.21.6"), ("scipy", "1.9.3")])
def test_old_numpy_or_scipy_warns_with_the_upgrade_command(monkeypatch, capsys, name, old):
    _fake_versions(monkeypatch, **{name: old})
    report = ck.check_environment()
    out = capsys.readouterr().out
    assert not report.ok
    assert f"WARNING: {name} {old} is older than the supported {envc.MINIMUM_VERSIONS[name]}" in out
    assert f'pip install -U "{name}>={envc.MINIMUM_VERSIONS[name]}"' in out


def test_missing_required_package_warns_but_missing_jupyterlab_does_not(monkeypatch):
    _fake_versions(monkeypatch, sympy=None, jupyterlab=None)
    warnings = ck.check_environment(show=False).warnings
    assert any("sympy is not installed" in w for w in warnings)
    assert not any("jupyterlab" in w.split(" ")[0] for w in warnings)


def test_missing_widget_frontend_warns_with_restart_advice(monkeypatch, capsys):
    monkeypatch.setattr(envc, "find_widget_frontend", lambda: None)
    report = ck.check_environment()
    out = capsys.readouterr().out
    assert report.widget_frontend is None
    assert "jupyterlab-manager) was not found" in out and "restart JupyterLab" in out


def test_old_widget_frontend_with_ipywidgets_8_warns(monkeypatch):
    monkeypatch.setattr(envc, "find_widget_frontend", lambda: "3.1.0")
    _fake_versions(monkeypatch, ipywidgets="8.1.0")
    assert any("too old for ipywidgets 8.1.0" in w for w in ck.check_environment(show=False).warnings)


def test_find_widget_frontend_reads_the_labextension_package(tmp_path):
    assert envc.find_widget_frontend([tmp_path]) is None
    pkg = tmp_path / "@jupyter-widgets" / "jupyterlab-manager"
    pkg.mkdir(parents=True)
    (pkg / "package.json").write_text(json.dumps({"name": "@jupyter-widgets/jupyterlab-manager",
                                                  "version": "5.0.9"}))
    assert envc.find_widget_frontend([tmp_path / "nothing", tmp_path]) == "5.0.9"


@pytest.mark.parametrize("text, expected", [("1.26.4", (1, 26, 4)), ("2.0.0rc1", (2, 0, 0)),
                                            ("1.10", (1, 10)), ("3.7.post1", (3, 7))])
def test_version_tuple(text, expected):
    assert envc._version_tuple(text) == expected


def test_minimum_versions_match_pyproject():
    text = (Path(__file__).parents[1] / "pyproject.toml").read_text()
    bounds = dict(re.findall(r'"([a-z]+)>=([\d.]+)"', text))
    for name, minimum in envc.MINIMUM_VERSIONS.items():
        assert bounds[name] == minimum, name


def test_show_must_be_bool():
    with pytest.raises(ValueError, match="show must be True or False"):
        ck.check_environment(show="yes")


# -- where the kernel runs: Colab, JupyterLite, Binder (simulated) -------------------------------

def _no_frontend_anywhere(monkeypatch, tmp_path):
    """No labextension directory holds anything: what a kernel without a JupyterLab extension sees."""
    monkeypatch.setattr(envc, "_labextension_dirs", lambda: [tmp_path])


def _forget_host(monkeypatch):
    for name in ("BINDER_LAUNCH_HOST", "BINDER_REQUEST", "BINDER_REPO_URL"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.delitem(sys.modules, "google.colab", raising=False)


def test_host_is_local_jupyter_here(monkeypatch):
    _forget_host(monkeypatch)
    assert envc.detect_host() == "jupyter"


def test_colab_does_not_warn_about_the_jupyterlab_frontend(monkeypatch, tmp_path, capsys):
    _forget_host(monkeypatch)
    _no_frontend_anywhere(monkeypatch, tmp_path)
    monkeypatch.setitem(sys.modules, "google.colab", type(sys)("google.colab"))
    report = ck.check_environment()
    out = capsys.readouterr().out
    assert report.host == "colab"
    assert report.ok, report.warnings
    assert "(Google Colab)" in out and "Colab's own widget manager" in out
    assert "WARNING" not in out


def test_jupyterlite_does_not_warn_and_says_it_cannot_tell(monkeypatch, tmp_path, capsys):
    _forget_host(monkeypatch)
    _no_frontend_anywhere(monkeypatch, tmp_path)
    monkeypatch.setattr(sys, "platform", "emscripten")
    report = ck.check_environment()
    out = capsys.readouterr().out
    assert report.host == "jupyterlite" and report.ok, report.warnings
    assert "not checkable from a JupyterLite kernel" in out


def test_binder_still_checks_the_frontend(monkeypatch, tmp_path):
    # Binder runs JupyterLab from the kernel's environment: a missing front-end is a real problem there
    _forget_host(monkeypatch)
    monkeypatch.setenv("BINDER_LAUNCH_HOST", "https://binder.example/")
    assert envc.detect_host() == "binder"
    assert ck.check_environment(show=False).ok   # the dev environment has the front-end
    _no_frontend_anywhere(monkeypatch, tmp_path)
    report = ck.check_environment(show=False)
    assert report.host == "binder"
    assert any("jupyterlab-manager) was not found" in w for w in report.warnings)


def test_colab_still_warns_about_old_packages(monkeypatch):
    _forget_host(monkeypatch)
    monkeypatch.setitem(sys.modules, "google.colab", type(sys)("google.colab"))
    _fake_versions(monkeypatch, ipywidgets="7.7.1")
    warnings = ck.check_environment(show=False).warnings
    assert any("ipywidgets 7.7.1 is older than the supported 8.0" in w for w in warnings)


def _labextension(base, name, version):
    pkg = base.joinpath(*name.split("/"))
    pkg.mkdir(parents=True)
    (pkg / "package.json").write_text(json.dumps({"name": name, "version": version}))


def test_anywidget_without_its_labextension_warns(monkeypatch, tmp_path):
    _forget_host(monkeypatch)
    _labextension(tmp_path, "@jupyter-widgets/jupyterlab-manager", "5.0.9")
    monkeypatch.setattr(envc, "_labextension_dirs", lambda: [tmp_path])
    _fake_versions(monkeypatch, anywidget="0.9.13")
    assert any("anywidget 0.9.13 is installed in the kernel but its JupyterLab extension was not found"
               in w for w in ck.check_environment(show=False).warnings)
    _labextension(tmp_path, "anywidget", "0.9.13")
    assert ck.check_environment(show=False).ok


def test_missing_anywidget_is_reported_once_as_a_missing_package(monkeypatch, tmp_path):
    _forget_host(monkeypatch)
    _labextension(tmp_path, "@jupyter-widgets/jupyterlab-manager", "5.0.9")
    monkeypatch.setattr(envc, "_labextension_dirs", lambda: [tmp_path])
    _fake_versions(monkeypatch, anywidget=None)
    warnings = ck.check_environment(show=False).warnings
    assert len(warnings) == 1 and warnings[0].startswith("anywidget is not installed"), warnings
