#pragma once
// The patch render's scene, built in memory (verify_render.cpp; docs/verify.md "Renders").
#include <filesystem>
#include <nlohmann/json.hpp>

#include "weft/scenes/description.h"
#include "weft/verify/verify.h"

namespace weft {

// A flat 1 m square of cloth, the object and material "cloth" bound to 'material' (its relative
// paths resolve against 'base_dir'), lit by a parallel light of irradiance kVerifyRenderIrradiance
// at normal incidence from the viewer's side or from behind ('transmission'), seen by an
// orthographic camera kVerifyRenderViewZenithDeg from the normal that frames the patch, with the
// render settings (render_size, render_spp, seed).
SceneDescription verify_render_scene(const nlohmann::json& material, bool transmission,
                                     const VerifySettings& settings,
                                     const std::filesystem::path& base_dir);

}  // namespace weft
