// The C++ side of python/tests/test_library_equal.py: evaluates or inverts points through the
// library's C++ API alone, one point at a time (Volume::evaluate, evaluate_jacobian,
// invert_certified and invert from the domain's centre, GlobalSolver::solve with the default
// parameters), so the module's
// bulk and parallel paths can be compared with it bit for bit.
//
//   trivox_python_reference MODEL TRIVARIATE MODE POINTS.f64 OUT.f64 [deboor]
//
// MODEL: a model file; TRIVARIATE: the index among its trivariates; POINTS.f64: N x 3 float64
// values (native byte order). OUT.f64 receives float64 values per point:
//   evaluate: x, y, z
//   jacobian: x, y, z, then J row by row (J[r][c] = dV_r / dp_c)
//   invert:   u, v, w, status, residual, iterations (invert_certified, Volume.invert's default)
//   newton:   the same from invert (Newton alone, Volume.invert(certified=False))
//   global:   status, boxes visited, preimage count k, then k x (u, v, w, residual, det)
// With `deboor` the volume keeps the de Boor kernel (VolumeOptions::power_form = false).
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "trivox/inverse/invert.h"
#include "trivox/io/model.h"
#include "trivox/spline/volume.h"

int main(int argc, char** argv) {
  using namespace trivox;
  if (argc != 6 && !(argc == 7 && std::string(argv[6]) == "deboor")) {
    std::fprintf(stderr, "usage: %s MODEL TRIVARIATE MODE POINTS.f64 OUT.f64 [deboor]\n", argv[0]);
    return 2;
  }
  try {
    const Model model = read_model(argv[1]);
    const std::vector<int> trivariates = model.volume_indices();
    const auto index = static_cast<std::size_t>(std::stoi(argv[2]));
    VolumeOptions options;
    options.power_form = argc != 7;
    const Volume volume(model.patches.at(static_cast<std::size_t>(trivariates.at(index))).spline, options);
    const std::string mode = argv[3];

    std::ifstream in(argv[4], std::ios::binary);
    std::vector<double> coords;
    for (double v; in.read(reinterpret_cast<char*>(&v), sizeof v);) coords.push_back(v);
    std::vector<double> out;
    const GlobalSolver solver(volume);
    for (std::size_t i = 0; i + 2 < coords.size(); i += 3) {
      const Vec3 p{coords[i], coords[i + 1], coords[i + 2]};
      if (mode == "evaluate") {
        const Vec3 x = volume.evaluate(p);
        out.insert(out.end(), {x.x, x.y, x.z});
      } else if (mode == "jacobian") {
        Vec3 x;
        Mat3 j;
        volume.evaluate_jacobian(p, x, j);
        out.insert(out.end(), {x.x, x.y, x.z});
        for (const auto& row : j.m) out.insert(out.end(), row.begin(), row.end());
      } else if (mode == "invert" || mode == "newton") {
        const Vec3 centre = volume.domain().center();
        const InverseResult r =
            mode == "invert" ? invert_certified(volume, solver, p, centre) : invert(volume, p, centre);
        out.insert(out.end(), {r.uvw.x, r.uvw.y, r.uvw.z, static_cast<double>(r.status), r.residual,
                               static_cast<double>(r.iterations)});
      } else if (mode == "global") {
        const GlobalResult r = solver.solve(p);
        out.insert(out.end(), {static_cast<double>(r.status), static_cast<double>(r.boxes_visited),
                               static_cast<double>(r.preimages.size())});
        for (const Preimage& q : r.preimages) out.insert(out.end(), {q.uvw.x, q.uvw.y, q.uvw.z, q.residual, q.det});
      } else {
        std::fprintf(stderr, "unknown mode '%s' (evaluate, jacobian, invert, newton, global)\n", mode.c_str());
        return 2;
      }
    }
    std::ofstream o(argv[5], std::ios::binary);
    o.write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size() * sizeof(double)));
    return o ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trivox_python_reference: %s\n", e.what());
    return 1;
  }
}
