"""recon_eval's feature result format (docs/features.md, "File format"): keypoint and match files,
their errors naming file and line, and the result-folder rules."""
import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.readers.features import read_feature_files, read_keypoints, read_matches


# --- the user format --------------------------------------------------------------------------
class TestReader:
    def test_text_comments_extra_columns_commas(self, tmp_path):
        p = tmp_path / "a.txt"
        p.write_text("# x y scale angle\n1.5 2.25 3 40\n\n  7, 8.5, 1, 2  # a comment\n9 10\n")
        np.testing.assert_array_equal(read_keypoints(p), [[1.5, 2.25], [7, 8.5], [9, 10]])

    def test_corner_origin_subtracts_half_a_pixel(self, tmp_path):
        p = tmp_path / "a.txt"
        p.write_text("0.5 0.5\n10 20.25\n")
        np.testing.assert_array_equal(read_keypoints(p, "corner"), [[0.0, 0.0], [9.5, 19.75]])
        q = tmp_path / "b.npy"
        np.save(q, np.array([[0.5, 0.5, 3.0]]))
        np.testing.assert_array_equal(read_keypoints(q, "corner"), [[0.0, 0.0]])

    def test_npy_and_empty_files(self, tmp_path):
        np.save(tmp_path / "k.npy", np.zeros((0, 2)))
        assert read_keypoints(tmp_path / "k.npy").shape == (0, 2)
        (tmp_path / "k.txt").write_text("# nothing\n")
        assert read_keypoints(tmp_path / "k.txt").shape == (0, 2)
        np.save(tmp_path / "m.npy", np.array([[0, 1], [2, 0]], np.int32))
        np.testing.assert_array_equal(read_matches(tmp_path / "m.npy", 3, 2), [[0, 1], [2, 0]])
        (tmp_path / "m.txt").write_text("0.000000000000000000e+00 1.000000000000000000e+00\n")  # numpy.savetxt default
        np.testing.assert_array_equal(read_matches(tmp_path / "m.txt", 3, 2), [[0, 1]])

    @pytest.mark.parametrize("text, expect", [
        ("1 2\n3 x\n", ":2: expected numbers x y, got '3' 'x'"),
        ("1 2\n3\n", ":2: expected at least 2 columns"),
        ("1 nan\n", ":1: x y must be finite"),
    ])
    def test_keypoint_errors_name_file_and_line(self, tmp_path, text, expect):
        p = tmp_path / "k.txt"
        p.write_text(text)
        with pytest.raises(InputError, match="k.txt" + expect.replace("(", r"\(")):
            read_keypoints(p)

    @pytest.mark.parametrize("text, expect", [
        ("0 1\n1 2 3\n", ":2: expected 2 columns (index_i index_j), got 3"),
        ("0 1.5\n", ":1: index_j must be an integer keypoint index, got 1.5"),
        ("0 one\n", ":1: index_j must be an integer keypoint index, got 'one'"),
        ("0 1\n3 0\n", ":2: index_i 3 out of range: ki.txt has 3 keypoints (valid 0..2)"),
        ("-1 0\n", ":1: index_i -1 out of range"),
    ])
    def test_match_errors_name_file_and_line(self, tmp_path, text, expect):
        p = tmp_path / "m.txt"
        p.write_text(text)
        with pytest.raises(InputError) as e:
            read_matches(p, 3, 2, "ki.txt", "kj.txt")
        assert f"m.txt{expect}" in str(e.value)

    def test_npy_errors_name_row(self, tmp_path):
        np.save(tmp_path / "m.npy", np.array([[0, 1], [0, 5]]))
        with pytest.raises(InputError, match=r"m.npy: row 1: index_j 5 out of range"):
            read_matches(tmp_path / "m.npy", 3, 2)
        np.save(tmp_path / "k.npy", np.array([1.0, 2.0]))
        with pytest.raises(InputError, match=r"k.npy: expected an array of shape \(N, k\), k >= 2"):
            read_keypoints(tmp_path / "k.npy")

    def test_folder_rules(self, tmp_path, write_feature_result):
        root = write_feature_result(tmp_path / "r", {"a_0000": np.zeros((2, 2))}, {("a_0000", "b_0001"): [[0, 0]]})
        with pytest.raises(InputError, match=r"a_0000__b_0001.txt: matches need the keypoints of view 'b_0001'"):
            read_feature_files(root, [], [("a_0000", "b_0001")])
        # without the match file: b has 0 keypoints, the pair 0 matches; both listed, never dropped
        (root / "matches" / "a_0000__b_0001.txt").unlink()
        f = read_feature_files(root, [], [("a_0000", "b_0001")])
        assert f.views_without_keypoints == ("b_0001",) and f.pairs_without_matches == ("a_0000__b_0001",)
        assert f.keypoints["b_0001"].shape == (0, 2) and f.matches[("a_0000", "b_0001")].shape == (0, 2)
        # a match file named the other way round is refused with the right name
        np.savetxt(root / "matches" / "b_0001__a_0000.txt", np.zeros((0, 2)))
        with pytest.raises(InputError, match=r"b_0001__a_0000.txt: the dataset pair is \(a_0000, b_0001\): "
                                             r"name the file a_0000__b_0001.txt"):
            read_feature_files(root, [], [("a_0000", "b_0001")])
        np.save(root / "keypoints" / "a_0000.npy", np.zeros((2, 2)))
        with pytest.raises(InputError, match="a_0000.txt and .*a_0000.npy: both exist"):
            read_feature_files(root, ["a_0000"], [])
