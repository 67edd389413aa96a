"""`python -m runtime view FOLDER` (runtime/scenarios/view.py): which page it opens, and what it refuses."""
import pytest

from runtime.scenarios import view

PAGE = '<!DOCTYPE html>\n<html><head><meta charset="utf-8">\n' + view.GENERATOR.decode() + "\n</head></html>"


def test_view_opens_the_replay_page_of_a_run_folder(tmp_path, monkeypatch, capsys):
    (tmp_path / "replay.html").write_text(PAGE)
    opened = []
    monkeypatch.setattr(view.webbrowser, "open", lambda url: opened.append(url) or True)
    assert view.main([str(tmp_path)]) == 0
    assert opened == [(tmp_path / "replay.html").resolve().as_uri()]
    assert opened[0] in capsys.readouterr().out


def test_view_accepts_the_page_itself(tmp_path, monkeypatch):
    page = tmp_path / "replay.html"
    page.write_text(PAGE)
    opened = []
    monkeypatch.setattr(view.webbrowser, "open", lambda url: opened.append(url) or True)
    assert view.main([str(page)]) == 0 and opened == [page.resolve().as_uri()]


def test_view_names_a_missing_folder_or_page_and_exits_2(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(view.webbrowser, "open", lambda url: (_ for _ in ()).throw(AssertionError("opened")))
    assert view.main([str(tmp_path / "nowhere")]) == 2
    assert "nowhere: no such folder" in capsys.readouterr().err
    assert view.main([str(tmp_path)]) == 2
    assert "replay.html: no replay page here" in capsys.readouterr().err


def test_view_says_so_when_no_browser_starts(tmp_path, monkeypatch, capsys):
    (tmp_path / "replay.html").write_text(PAGE)
    monkeypatch.setattr(view.webbrowser, "open", lambda url: False)
    assert view.main([str(tmp_path)]) == 2
    assert "no browser could be started" in capsys.readouterr().err


@pytest.mark.parametrize("content", [b"<html></html>", b"time,x\n0,1\n", b"\xff\xfe not text"])
def test_view_refuses_a_file_that_is_not_a_replay_page(tmp_path, monkeypatch, capsys, content):
    monkeypatch.setattr(view.webbrowser, "open", lambda url: (_ for _ in ()).throw(AssertionError("opened")))
    (tmp_path / "trajectory.csv").write_bytes(content)
    assert view.main([str(tmp_path / "trajectory.csv")]) == 2
    assert "trajectory.csv: not a replay page" in capsys.readouterr().err


def test_a_written_replay_page_carries_the_mark_view_looks_for():
    from runtime.scenarios.replay import TEMPLATE
    assert view.GENERATOR in TEMPLATE.read_bytes()[:1024]
