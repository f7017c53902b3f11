"""File formats: FOLD 1.2 crease patterns."""

from rigidfold.io.fold import FoldData, fold_dict, pattern_from_fold, read_fold, write_fold

__all__ = ["FoldData", "fold_dict", "pattern_from_fold", "read_fold", "write_fold"]
