#pragma once

#include <deal.II/dofs/dof_handler.h>

#include <algorithm>
#include <vector>

namespace rotorfit
{
  /**
   * Cell-local indices of the DoFs that live on face @p face_no of @p cell
   * (a DoFHandler's active cell, 2D or 3D).
   * Found through the face's own DoF indices: FESystem::has_support_on_face
   * is not reliable for simplex elements in deal.II 9.4.
   */
  template <typename CellIterator>
  inline std::vector<unsigned int>
  cell_dofs_on_face(const CellIterator &cell, const unsigned int face_no)
  {
    const auto &fe = cell->get_fe();
    std::vector<dealii::types::global_dof_index> cell_dofs(fe.n_dofs_per_cell());
    std::vector<dealii::types::global_dof_index> face_dofs(
      fe.n_dofs_per_face(face_no));
    cell->get_dof_indices(cell_dofs);
    cell->face(face_no)->get_dof_indices(face_dofs);
    std::vector<unsigned int> local;
    for (unsigned int i = 0; i < cell_dofs.size(); ++i)
      if (std::find(face_dofs.begin(), face_dofs.end(), cell_dofs[i]) !=
          face_dofs.end())
        local.push_back(i);
    return local;
  }
} // namespace rotorfit
