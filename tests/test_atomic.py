"""Atomic writes: nothing but the file is created, and an error names the file asked for, not the temporary one."""

import errno
import os

import pytest

from drumstroke._atomic import write_atomic


def test_a_write_replaces_the_file_whole_and_keeps_its_permissions(tmp_path):
    path = tmp_path / "a.txt"
    path.write_text("old")
    path.chmod(0o640)
    write_atomic(path, "new")
    assert path.read_text() == "new" and path.stat().st_mode & 0o777 == 0o640
    assert list(tmp_path.iterdir()) == [path]


def test_a_missing_folder_is_an_error_naming_the_file_and_is_not_created(tmp_path):
    path = tmp_path / "no" / "such" / "a.txt"
    with pytest.raises(FileNotFoundError) as caught:
        write_atomic(path, "x")
    assert caught.value.filename == str(path) and caught.value.errno == errno.ENOENT
    assert list(tmp_path.iterdir()) == []


def test_writing_onto_a_directory_names_it_and_leaves_no_temporary(tmp_path):
    (tmp_path / "d").mkdir()
    with pytest.raises(IsADirectoryError) as caught:
        write_atomic(tmp_path / "d", b"x")
    assert caught.value.filename == str(tmp_path / "d")
    assert list(tmp_path.iterdir()) == [tmp_path / "d"] and list((tmp_path / "d").iterdir()) == []


def test_a_full_disk_names_the_file_with_the_reason_and_keeps_the_old_one(tmp_path, monkeypatch):
    path = tmp_path / "a.txt"
    path.write_text("old")

    def full(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(OSError, match="No space left on device") as caught:
        write_atomic(path, "new")
    assert caught.value.filename == str(path) and caught.value.errno == errno.ENOSPC
    assert path.read_text() == "old" and list(tmp_path.iterdir()) == [path]
