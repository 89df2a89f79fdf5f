#pragma once
// Where an interaction that is not a pair law (the channel's fluid layer) writes its entries of
// the force balance: the solver's ResistanceSystem implements it, so the interaction needs no
// knowledge of the solver (the data flow runs interactions -> solver, not back).

namespace sheardiff {

class SystemEntries {
 public:
  // One entry of the matrix (row >= col, in the pattern the interaction declared) and of the
  // right-hand side, added to what is there.
  virtual void add_value(int row, int col, double v) = 0;
  virtual void add_rhs(int row, double v) = 0;

 protected:
  ~SystemEntries() = default;
};

}  // namespace sheardiff
