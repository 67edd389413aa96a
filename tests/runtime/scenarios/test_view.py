"""`python -m runtime view FOLDER` (runtime/scenarios/view.py): which page it opens, and what it refuses."""
from runtime.scenarios import view


def test_view_opens_the_replay_page_of_a_run_folder(tmp_path, monkeypatch, capsys):
    (tmp_path / "replay.html").write_text("<html></html>")
    opened = []
    monkeypatch.setattr(view.webbrowser, "open", lambda url: opened.append(url) or True)
    assert view.main([str(tmp_path)]) == 0
    assert opened == [(tmp_path / "replay.html").resolve().as_uri()]
    assert opened[0] in capsys.readouterr().out


def test_view_accepts_the_page_itself(tmp_path, monkeypatch):
    page = tmp_path / "replay.html"
    page.write_text("<html></html>")
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
    (tmp_path / "replay.html").write_text("<html></html>")
    monkeypatch.setattr(view.webbrowser, "open", lambda url: False)
    assert view.main([str(tmp_path)]) == 2
    assert "no browser could be started" in capsys.readouterr().err
