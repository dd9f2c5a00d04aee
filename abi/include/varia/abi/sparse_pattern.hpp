// The pattern of a sparse Hessian assembled from blocks (Lagrangian::hessian_pattern): the distinct
// (row, col) entries, in the order they were first named, each with its slot in the values array.
// A block (an effect of a composite, a term of a term-wise Lagrangian) keeps the slot of each of its
// entries and adds its values there, so that blocks sharing an entry sum into it.
#pragma once

#include <map>
#include <utility>
#include <vector>

namespace varia {

class SparsePattern {
 public:
  // The slot of entry (row, col), appended when new.
  int slot(int row, int col) {
    const auto [it, inserted] = slots_.try_emplace({row, col}, static_cast<int>(rows_.size()));
    if (inserted) {
      rows_.push_back(row);
      cols_.push_back(col);
    }
    return it->second;
  }
  // The entries, as Lagrangian::hessian_pattern gives them.
  int entries(const int** rows, const int** cols) const noexcept {
    *rows = rows_.data();
    *cols = cols_.data();
    return size();
  }
  int size() const noexcept { return static_cast<int>(rows_.size()); }

 private:
  std::map<std::pair<int, int>, int> slots_;
  std::vector<int> rows_, cols_;
};

}  // namespace varia
