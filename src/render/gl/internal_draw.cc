// The colour pass and the truth pass: the same items, visited front to back, culled against
// the view's frustum, at the same levels of detail, so that the truth's silhouettes are the
// colour image's.
#include <algorithm>

#include "render/gl/internal_gl_renderer_impl.h"
#include "render/gl/internal_lod.h"
#include "render/gl/internal_shaders.h"

namespace saccade::render::gl {

void GlRenderer::SortItems(const Eigen::Isometry3d& X_EW) {
  // Objects front to back (the depth test then spares hidden fragments their shading).
  order_.clear();
  for (std::size_t i = 0; i < items_.size(); ++i) {
    const Eigen::Vector3d c =
        X_EW * (item_poses_[i] * items_[i].center_model.cwiseProduct(items_[i].scale));
    order_.emplace_back(-c.z(), static_cast<int>(i));
  }
  std::sort(order_.begin(), order_.end());
}

// Calls visit(item, MV, mvp, pixels per model unit) for every item not outside the view's
// frustum (and, with `cull`, not outside the frustum of cull * mvp: a part of the view),
// front to back.
template <class Visit>
void GlRenderer::ForEachVisibleItem(const ViewSetup& view, double near,
                                    const Eigen::Isometry3d& X_EW, Visit&& visit,
                                    const Eigen::Matrix4d* cull) {
  SortItems(X_EW);
  for (const auto& [depth, index] : order_) {
    const DrawItem& item = items_[index];
    Eigen::Affine3d MV = X_EW * item_poses_[index];
    MV.linear() = MV.linear() * item.scale.asDiagonal();
    const Eigen::Matrix4d mvp = view.projection * MV.matrix();
    if (!item.model->bounds.isEmpty() &&
        (OutsideFrustum(mvp, item.model->bounds) ||
         (cull != nullptr && OutsideFrustum(*cull * mvp, item.model->bounds)))) {
      continue;
    }
    visit(item, MV, mvp, PixelsPerModelUnit(item, depth, view.focal, near));
  }
}

const GpuLod& GlRenderer::LodOf(const GpuMesh& mesh, double px_per_model_unit) const {
  return mesh.levels[ChooseLod(mesh.errors, px_per_model_unit, options_.lod_max_error_px)];
}

void GlRenderer::DrawLod(const GpuMesh& mesh, const GpuLod& lod, bool* culling) {
  if (mesh.closed != *culling) {
    *culling = mesh.closed;
    *culling ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
  }
  glBindVertexArray(mesh.vao);
  glDrawElements(GL_TRIANGLES, lod.index_count, mesh.index_type,
                 reinterpret_cast<const void*>(lod.offset_bytes));
}

void GlRenderer::DrawGround(GLint mvp, GLint mv, const Eigen::Matrix4d& P,
                            const Eigen::Isometry3d& X_EW) {
  const auto mvp_f = ToFloat<4>(Eigen::Matrix4d(P * X_EW.matrix()));
  const auto mv_f = ToFloat<4>(X_EW.matrix());
  glUniformMatrix4fv(mvp, 1, GL_FALSE, mvp_f.data());
  glUniformMatrix4fv(mv, 1, GL_FALSE, mv_f.data());
  glBindVertexArray(ground_vao_);
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

void GlRenderer::DrawScene(const ViewSetup& view, double near, const geometry::Pose& X_WV,
                           const Eigen::Matrix4d* cull) {
  ++camera_pass_;
  const Eigen::Isometry3d X_EW = EyeFromWorld(X_WV);
  MeshProgram* program = nullptr;
  const GpuMaterial* material_set = nullptr;
  GLuint bound_texture = 0;
  bool culling = false;
  glDisable(GL_CULL_FACE);
  ForEachVisibleItem(
      view, near, X_EW,
      [&](const DrawItem& item, const Eigen::Affine3d& MV, const Eigen::Matrix4d& mvp,
          double px_per_unit) {
        const auto mvp_f = ToFloat<4>(mvp);
        const auto mv_f = ToFloat<4>(MV.matrix());
        const auto normal_f = ToFloat<3>(Eigen::Matrix3d(MV.linear().inverse().transpose()));
        bool matrices_set = false;
        for (const GpuMesh& mesh : item.model->meshes) {
          const GpuMaterial& material = item.model->materials[mesh.material];
          const GpuLod& lod = LodOf(mesh, px_per_unit);
          const bool shiny = material.specular > 0.0f;
          const bool per_vertex = (mesh.flat && !shiny && point_lights_.empty()) ||
                                  lod.mean_edge * px_per_unit <= kPerVertexMaxEdgePx;
          const int variant = (material.texture != 0 ? kTextured : 0) | (shiny ? kShiny : 0) |
                              (per_vertex ? kPerVertex | (mesh.closed ? 0 : kTwoSided) : 0);
          MeshProgram& wanted = GetMeshProgram(variant);
          if (&wanted != program) {
            program = &wanted;
            glUseProgram(program->program);
            if (program->lights_pass != camera_pass_) {
              SetLights(program->lights, X_EW);
              program->lights_pass = camera_pass_;
            }
            matrices_set = false;
            material_set = nullptr;
          }
          if (!matrices_set) {
            glUniformMatrix4fv(program->mvp, 1, GL_FALSE, mvp_f.data());
            glUniformMatrix4fv(program->mv, 1, GL_FALSE, mv_f.data());
            glUniformMatrix3fv(program->normal, 1, GL_FALSE, normal_f.data());
            matrices_set = true;
          }
          if (&material != material_set) {
            glUniform4fv(program->base_color, 1, material.base_color.data());
            glUniform1f(program->specular, material.specular);
            glUniform1f(program->shininess, material.shininess);
            material_set = &material;
          }
          if (material.texture != 0 && material.texture != bound_texture) {
            glBindTexture(GL_TEXTURE_2D, material.texture);
            bound_texture = material.texture;
          }
          DrawLod(mesh, lod, &culling);
        }
      },
      cull);
  if (culling) glDisable(GL_CULL_FACE);

  if (draw_ground_) {
    glUseProgram(ground_.program);
    SetLights(ground_.lights, X_EW);
    const Eigen::Vector3f normal_eye = (X_EW.linear() * Eigen::Vector3d::UnitZ()).cast<float>();
    glUniform3fv(ground_.normal_eye, 1, normal_eye.data());
    DrawGround(ground_.mvp, ground_.mv, view.projection, X_EW);
  }
  glBindVertexArray(0);
}

void GlRenderer::DrawTruth(const ViewSetup& view, double near, const geometry::Pose& X_WV) {
  const Eigen::Isometry3d X_EW = EyeFromWorld(X_WV);
  const EffectPrograms::Truth& truth = effect_programs_->truth();
  glUseProgram(truth.program);
  glUniform3fv(truth.depth_axis, 1, view.depth_axis.data());
  bool culling = false;
  glDisable(GL_CULL_FACE);
  ForEachVisibleItem(view, near, X_EW,
                     [&](const DrawItem& item, const Eigen::Affine3d& MV,
                         const Eigen::Matrix4d& mvp, double px_per_unit) {
                       const auto mvp_f = ToFloat<4>(mvp);
                       const auto mv_f = ToFloat<4>(MV.matrix());
                       glUniformMatrix4fv(truth.mvp, 1, GL_FALSE, mvp_f.data());
                       glUniformMatrix4fv(truth.mv, 1, GL_FALSE, mv_f.data());
                       glUniform1ui(truth.id, ItemId(item));
                       for (const GpuMesh& mesh : item.model->meshes)
                         DrawLod(mesh, LodOf(mesh, px_per_unit), &culling);
                     });
  if (culling) glDisable(GL_CULL_FACE);
  if (draw_ground_) {
    // The ground is a surface (it has depth) but not an object (id 0).
    glUniform1ui(truth.id, 0u);
    DrawGround(truth.mvp, truth.mv, view.projection, X_EW);
  }
  glBindVertexArray(0);
}

}  // namespace saccade::render::gl
