// 3MF meshes through lib3mf (1.x, its C interface): every build item, each object it names
// instanced with the item's transform and, for a components object, each component's
// transform, down to the mesh objects; in millimetres by the model's unit. Only objects of
// type "model" are solid: support and other objects are skipped, as a printer would not
// print them as part.
//
// 3MF transforms are written as 3 x 4 matrices; lib3mf gives them as m_fFields[row][col]
// with x'_i = sum_j m[i][j] x_j + m[i][3] (the file's "m00 m01 m02 m10 ... m32", for row
// vectors, transposed).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Model/COM/NMR_DLLInterfaces.h>
#include <fmt/format.h>

#include "io/mesh_builder.h"
#include "trivox/error.h"
#include "trivox/limits.h"

namespace trivox::io_detail {

namespace {

using namespace NMR;

struct Release {
  void operator()(PLib3MFBase* p) const noexcept {
    if (p != nullptr) lib3mf_release(p);
  }
};
using Handle = std::unique_ptr<void*, Release>;

class Reader3mf {
 public:
  Reader3mf(MeshBuilder& builder, const std::string& source) : builder_(builder), source_(source) {}

  void read(std::vector<std::uint8_t>& bytes) {
    PLib3MFModel* model = nullptr;
    check(lib3mf_createmodel(&model), nullptr, "creating a model");
    model_.reset(model);
    PLib3MFModelReader* reader = nullptr;
    check(lib3mf_model_queryreader(model, "3mf", &reader), model, "creating a reader");
    const Handle reader_handle(reader);
    if (bytes.empty()) throw InputError(source_, 0, "3MF", "the file is empty");
    check(lib3mf_reader_readfrombuffer(reader, bytes.data(), bytes.size()), reader, "reading the package");
    DWORD unit = MODELUNIT_MILLIMETER;
    check(lib3mf_model_getunit(model, &unit), model, "reading the unit");
    switch (unit) {
      case MODELUNIT_MICROMETER: to_mm_ = 1e-3; break;
      case MODELUNIT_MILLIMETER: to_mm_ = 1; break;
      case MODELUNIT_CENTIMETER: to_mm_ = 10; break;
      case MODELUNIT_INCH: to_mm_ = 25.4; break;
      case MODELUNIT_FOOT: to_mm_ = 304.8; break;
      case MODELUNIT_METER: to_mm_ = 1000; break;
      default: throw InputError(source_, 0, "3MF", fmt::format("unknown unit {}", unit));
    }
    PLib3MFModelBuildItemIterator* items = nullptr;
    check(lib3mf_model_getbuilditems(model, &items), model, "listing the build items");
    const Handle items_handle(items);
    int number = 0;
    for (;;) {
      BOOL more = false;
      check(lib3mf_builditemiterator_movenext(items, &more), items, "listing the build items");
      if (!more) break;
      ++number;
      PLib3MFModelBuildItem* item = nullptr;
      check(lib3mf_builditemiterator_getcurrent(items, &item), items, "reading a build item");
      const Handle item_handle(item);
      MeshTransform place;
      BOOL has = false;
      check(lib3mf_builditem_hasobjecttransform(item, &has), item, "reading a build item");
      if (has) {
        MODELTRANSFORM t;
        check(lib3mf_builditem_getobjecttransform(item, &t), item, "reading a build item's transform");
        place = transform(t);
      }
      PLib3MFModelObjectResource* object = nullptr;
      check(lib3mf_builditem_getobjectresource(item, &object), item, "reading a build item's object");
      const Handle object_handle(object);
      add_object(object, place.scaled(to_mm_), fmt::format("build item {}", number), 0);
    }
  }

 private:
  static MeshTransform transform(const MODELTRANSFORM& t) {
    MeshTransform m;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) m.m[i][j] = t.m_fFields[i][j];
      m.t[i] = t.m_fFields[i][3];
    }
    return m;
  }

  void check(LIB3MFRESULT result, PLib3MFBase* from, const char* doing) const {
    if (result == LIB3MF_OK) return;
    std::string message;
    if (from != nullptr) {
      DWORD code = 0;
      LPCSTR text = nullptr;
      if (lib3mf_getlasterror(from, &code, &text) == LIB3MF_OK && text != nullptr)
        message = fmt::format(": {} (lib3mf error {:#x})", text, code);
    }
    if (message.empty()) message = fmt::format(" (lib3mf result {:#x})", static_cast<std::uint32_t>(result));
    throw InputError(source_, 0, "3MF", fmt::format("{} failed{}", doing, message));
  }

  void add_object(PLib3MFModelObjectResource* object, const MeshTransform& place, const std::string& where, int depth) {
    // lib3mf refuses components that refer to themselves; the depth bounds a deep chain.
    if (depth > 32) throw InputError(source_, 0, where, "components nest more than 32 deep");
    DWORD type = 0;
    check(lib3mf_object_gettype(object, &type), object, "reading an object's type");
    BOOL is_mesh = false, is_components = false;
    check(lib3mf_object_ismeshobject(object, &is_mesh), object, "reading an object");
    check(lib3mf_object_iscomponentsobject(object, &is_components), object, "reading an object");
    if (is_mesh) {
      if (type != MODELOBJECTTYPE_MODEL) return;
      add_mesh(object, place, where);
    } else if (is_components) {
      DWORD count = 0;
      check(lib3mf_componentsobject_getcomponentcount(object, &count), object, "reading components");
      for (DWORD c = 0; c < count; ++c) {
        PLib3MFModelComponent* component = nullptr;
        check(lib3mf_componentsobject_getcomponent(object, c, &component), object, "reading a component");
        const Handle component_handle(component);
        MeshTransform local;
        BOOL has = false;
        check(lib3mf_component_hastransform(component, &has), component, "reading a component");
        if (has) {
          MODELTRANSFORM t;
          check(lib3mf_component_gettransform(component, &t), component, "reading a component's transform");
          local = transform(t);
        }
        PLib3MFModelObjectResource* child = nullptr;
        check(lib3mf_component_getobjectresource(component, &child), component, "reading a component's object");
        const Handle child_handle(child);
        add_object(child, place.after(local), fmt::format("{}, component {}", where, c + 1), depth + 1);
      }
    }
  }

  void add_mesh(PLib3MFModelMeshObject* mesh, const MeshTransform& place, const std::string& where) {
    DWORD nv = 0, nt = 0;
    check(lib3mf_meshobject_getvertexcount(mesh, &nv), mesh, "reading a mesh");
    check(lib3mf_meshobject_gettrianglecount(mesh, &nt), mesh, "reading a mesh");
    builder_.expect(nt, nv, where);
    std::vector<MODELMESHVERTEX> vertices(nv);
    std::vector<MODELMESHTRIANGLE> triangles(nt);
    DWORD got = 0;
    if (nv > 0) check(lib3mf_meshobject_getvertices(mesh, vertices.data(), nv, &got), mesh, "reading vertices");
    if (nt > 0)
      check(lib3mf_meshobject_gettriangleindices(mesh, triangles.data(), nt, &got), mesh, "reading triangles");
    std::vector<int> index(nv, -1);
    for (DWORD t = 0; t < nt; ++t) {
      int v[3];
      for (int c = 0; c < 3; ++c) {
        const DWORD i = triangles[t].m_nIndices[c];
        if (i >= nv) throw InputError(source_, 0, where, fmt::format("triangle {} names vertex {} of {}", t, i, nv));
        if (index[i] < 0) {
          const float* p = vertices[i].m_fPosition;
          index[i] = builder_.vertex(place.apply({p[0], p[1], p[2]}), where);
        }
        v[c] = index[i];
      }
      builder_.triangle(v[0], v[1], v[2]);
    }
  }

  MeshBuilder& builder_;
  const std::string& source_;
  double to_mm_ = 1;
  Handle model_;
};

}  // namespace

void read_3mf(std::vector<std::uint8_t> bytes, MeshBuilder& builder, const std::string& source) {
  Reader3mf(builder, source).read(bytes);
}

}  // namespace trivox::io_detail
