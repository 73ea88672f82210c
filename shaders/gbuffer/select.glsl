// Whether a G-buffer pixel is one of the selected materials' or shading models' (the defines
// of deferred.api.select_surfaces: SELECT_MATERIALS, SELECT_SHADING_MODELS, type ids).
#include "common/surface.glsl"

bool surface_selected(float surface_id) {
    if (surface_id < 0.5) return false;  // the background
#ifdef SELECT_MATERIALS
    const float selected_materials[] = float[](SELECT_MATERIALS);
    float material = surface_material_id(surface_id);
    for (int k = 0; k < selected_materials.length(); ++k) {
        if (abs(material - selected_materials[k]) < 0.5) return true;
    }
#endif
#ifdef SELECT_SHADING_MODELS
    const int selected_models[] = int[](SELECT_SHADING_MODELS);
    int model = surface_shading_model(surface_id);
    for (int k = 0; k < selected_models.length(); ++k) {
        if (model == selected_models[k]) return true;
    }
#endif
    return false;
}

bool pixel_selected(sampler2D normal_exponent_id, ivec2 pixel) {
    return surface_selected(texelFetch(normal_exponent_id, pixel, 0).w);
}
