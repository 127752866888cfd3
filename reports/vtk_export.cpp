#include "reports/vtk_export.hpp"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <unordered_map>

namespace rocklab::reports {

namespace {

void write(vtkPolyData* pd, const std::string& path) {
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetFileName(path.c_str());
  w->SetInputData(pd);
  w->SetDataModeToAppended();
  w->EncodeAppendedDataOff();
  if (!w->Write()) throw std::runtime_error("cannot write '" + path + "'");
}

vtkNew<vtkDoubleArray> vectors(const char* name) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->SetNumberOfComponents(3);
  return a;
}

vtkNew<vtkDoubleArray> scalars(const char* name) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  return a;
}

// Lines between particles given by slot, with per-line normal and tangential force.
void writeLinks(const Frame& f, const std::vector<Frame::Link>& links,
                const std::unordered_map<std::uint32_t, std::size_t>& index, const char* tangential,
                const std::vector<std::uint8_t>* kinds, const std::string& path) {
  vtkNew<vtkPoints> pts;
  for (const auto& p : f.pos) pts->InsertNextPoint(p[0], p[1], p[2]);
  vtkNew<vtkCellArray> lines;
  auto normal = scalars("normal_force");
  auto tang = scalars(tangential);
  vtkNew<vtkIntArray> kind;
  kind->SetName("kind");
  for (std::size_t k = 0; k < links.size(); ++k) {
    const vtkIdType ids[2] = {static_cast<vtkIdType>(index.at(links[k].a)),
                              static_cast<vtkIdType>(index.at(links[k].b))};
    lines->InsertNextCell(2, ids);
    normal->InsertNextValue(links[k].normal);
    tang->InsertNextValue(links[k].tangential);
    if (kinds) kind->InsertNextValue((*kinds)[k]);
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetLines(lines);
  pd->GetCellData()->AddArray(normal);
  pd->GetCellData()->AddArray(tang);
  if (kinds) pd->GetCellData()->AddArray(kind);
  write(pd, path);
}

}  // namespace

std::vector<PvdEntry> writeFrameVtk(const Frame& f, const Frame* reference, const std::string& dir,
                                    const std::string& stem) {
  std::unordered_map<std::uint32_t, std::size_t> index, ref_index;
  for (std::size_t i = 0; i < f.size(); ++i) index[f.slot[i]] = i;
  if (reference) {
    for (std::size_t i = 0; i < reference->size(); ++i) ref_index[reference->slot[i]] = i;
  }

  // Particles as vertices with their fields; apply ParaView's Glyph (sphere, scale by
  // radius) to see them as balls.
  vtkNew<vtkPoints> pts;
  vtkNew<vtkCellArray> verts;
  auto radius = scalars("radius");
  auto vel = vectors("velocity");
  auto disp = vectors("displacement");
  auto spin = scalars("spin");
  vtkNew<vtkIntArray> id;
  id->SetName("id");
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto& p = f.pos[i];
    const vtkIdType v = pts->InsertNextPoint(p[0], p[1], p[2]);
    verts->InsertNextCell(1, &v);
    radius->InsertNextValue(f.radius[i]);
    vel->InsertNextTuple(f.vel[i].data());
    double u[3] = {0.0, 0.0, 0.0};
    if (reference) {
      auto it = ref_index.find(f.slot[i]);
      if (it != ref_index.end()) {
        for (int d = 0; d < 3; ++d) u[d] = p[d] - reference->pos[it->second][d];
      }
    }
    disp->InsertNextTuple(u);
    spin->InsertNextValue(f.spin[i]);
    id->InsertNextValue(static_cast<int>(f.slot[i]));
  }
  vtkNew<vtkPolyData> particles;
  particles->SetPoints(pts);
  particles->SetVerts(verts);
  particles->GetPointData()->AddArray(radius);
  particles->GetPointData()->AddArray(vel);
  particles->GetPointData()->AddArray(disp);
  particles->GetPointData()->AddArray(spin);
  particles->GetPointData()->AddArray(id);
  particles->GetPointData()->SetActiveScalars("radius");
  std::vector<PvdEntry> out;
  const std::string base = dir + "/" + stem;
  write(particles, base + "_particles.vtp");
  out.push_back({f.time, 0, stem + "_particles.vtp"});
  writeLinks(f, f.contacts, index, "tangential_force", nullptr, base + "_contacts.vtp");
  out.push_back({f.time, 1, stem + "_contacts.vtp"});
  writeLinks(f, f.bonds, index, "shear_force", &f.bond_kind, base + "_bonds.vtp");
  out.push_back({f.time, 2, stem + "_bonds.vtp"});

  // Walls as squares spanning the box the walls make (walls are infinite planes).
  std::array<double, 3> lo{}, hi{};
  for (int d = 0; d < 3; ++d) lo[d] = 1e300, hi[d] = -1e300;
  for (const auto& w : f.walls) {
    for (int d = 0; d < 3; ++d) {
      if (std::abs(w.normal[d]) > 0.5)
        lo[d] = std::min(lo[d], w.point[d]), hi[d] = std::max(hi[d], w.point[d]);
    }
  }
  for (int d = 0; d < 3; ++d) {
    if (lo[d] > hi[d]) lo[d] = hi[d] = 0.0;  // a 2D scene has no z walls
  }
  vtkNew<vtkPoints> wpts;
  vtkNew<vtkCellArray> quads;
  vtkNew<vtkIntArray> wall_id;
  wall_id->SetName("wall");
  for (std::size_t k = 0; k < f.walls.size(); ++k) {
    const auto& w = f.walls[k];
    int a = 0;
    while (a < 3 && std::abs(w.normal[a]) < 0.5) ++a;
    if (a == 3) continue;  // not axis-aligned: not drawn
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    vtkIdType ids[4];
    const double corners[4][2] = {{lo[b], lo[c]}, {hi[b], lo[c]}, {hi[b], hi[c]}, {lo[b], hi[c]}};
    for (int q = 0; q < 4; ++q) {
      double p[3];
      p[a] = w.point[a];
      p[b] = corners[q][0];
      p[c] = corners[q][1];
      ids[q] = wpts->InsertNextPoint(p);
    }
    quads->InsertNextCell(4, ids);
    wall_id->InsertNextValue(static_cast<int>(k));
  }
  vtkNew<vtkPolyData> walls;
  walls->SetPoints(wpts);
  walls->SetPolys(quads);
  walls->GetCellData()->AddArray(wall_id);
  write(walls, base + "_walls.vtp");
  out.push_back({f.time, 3, stem + "_walls.vtp"});
  return out;
}

void writePvd(const std::string& path, const std::vector<PvdEntry>& entries) {
  std::ofstream out(path);
  out.precision(12);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  for (const PvdEntry& e : entries) {
    out << "    <DataSet timestep=\"" << e.time << "\" group=\"\" part=\"" << e.part << "\" file=\""
        << e.file << "\"/>\n";
  }
  out << "  </Collection>\n</VTKFile>\n";
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
}

}  // namespace rocklab::reports
