// SPDX-License-Identifier: Apache-2.0
// tools/umbra_view/panel.cpp: umbra-view's panel, Dear ImGui with Debian's GLFW and OpenGL 3
// backends (libimgui-dev builds both into libimgui.a). The frame itself is drawn as the first
// thing of the GUI's draw list, 1:1 from the texture present.c filled; the panel then goes over
// it. The technique section walks the technique registry (umbra/registry.h): every technique and
// every parameter with its type, range or allowed values, what 0 means and its doc come from
// there, so it names no technique or parameter itself. Everything it edits goes into the viewer's copies of the settings and marks
// them changed; main.c sets them on the renderer before the next frame.
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "view.h"

namespace {

const char *timing_name(umbra_timing t)
{
    return t == UMBRA_TIMING_DEVICE ? "device" : t == UMBRA_TIMING_WALL ? "wall" : "none";
}

// The file name of a preset's path.
const char *base_name(const char *path)
{
    const char *slash = std::strrchr(path, '/');
    return slash ? slash + 1 : path;
}

// A parameter's tooltip: its key, type and the description umbra-render's --help gives it.
void tooltip(const umbra_param_info *p)
{
    if (!ImGui::IsItemHovered())
        return;
    char text[1024];
    param_describe(p, text, sizeof text);
    const char *type = p->type == UMBRA_PARAM_FLOAT  ? "number"
                       : p->type == UMBRA_PARAM_UINT ? "whole number"
                                                     : "on or off";
    ImGui::SetTooltip("%s (%s%s): %s", p->key, type,
                      p->flags & UMBRA_PARAM_REBUILDS ? ", rebuilds the shadow structure" : "",
                      text);
}

// The parameter's value in d (technique t's); its default if the registry cannot read it.
double param_value(const umbra_shadow_desc *d, const umbra_technique_info *t,
                   const umbra_param_info *p)
{
    double value = p->default_value;
    umbra_shadow_desc_get_param(d, t->name, p->key, &value);
    return value;
}

// Sets the parameter through the registry, which checks it; a refusal is shown in the panel
// and leaves d as it was.
bool param_store(viewer *v, const umbra_technique_info *t, const umbra_param_info *p,
                 double value)
{
    char msg[sizeof v->message];
    if (umbra_shadow_desc_set_param(&v->s.shadow, t->name, p->key, value, msg, sizeof msg) !=
        UMBRA_SUCCESS) {
        std::snprintf(v->message, sizeof v->message, "%s", msg);
        v->message_is_error = 1;
        return false;
    }
    return true;
}

// The slider's ends: the range, moved in from a bound the range excludes.
void param_bounds(const umbra_param_info *p, double *lo, double *hi)
{
    double inset = p->type == UMBRA_PARAM_FLOAT ? 1e-3 * (p->max - p->min) : 1.0;
    *lo = p->flags & UMBRA_PARAM_MIN_EXCLUSIVE ? p->min + inset : p->min;
    *hi = p->flags & UMBRA_PARAM_MAX_EXCLUSIVE ? p->max - inset : p->max;
}

// The value a parameter whose 0 has a meaning takes when its checkbox leaves 0: the default if
// that is not 0, else the middle of the range (geometric for a positive range) or the middle
// allowed value.
double param_nonzero(const umbra_param_info *p)
{
    if (p->default_value != 0.0)
        return p->default_value;
    if (p->allowed)
        return p->allowed[p->allowed_count / 2];
    double lo, hi;
    param_bounds(p, &lo, &hi);
    double mid = lo > 0.0 ? std::sqrt(lo * hi) : 0.5 * (lo + hi);
    return p->type == UMBRA_PARAM_FLOAT ? mid : std::round(mid);
}

// One control for parameter p of technique t, by its type and range; true when it changed.
bool param_control(viewer *v, const umbra_technique_info *t, const umbra_param_info *p)
{
    const double value = param_value(&v->s.shadow, t, p);
    bool changed = false;
    ImGui::PushID(p->key);
    if (p->type == UMBRA_PARAM_BOOL) {
        bool b = value != 0.0;
        if (ImGui::Checkbox(p->key, &b))
            changed = param_store(v, t, p, b ? 1.0 : 0.0);
        tooltip(p);
        ImGui::PopID();
        return changed;
    }
    // A parameter whose 0 means "auto" (or the like) gets a checkbox for that in front of its
    // control; the control then shows the meaning and is disabled.
    const bool zero_allowed = (p->flags & UMBRA_PARAM_ZERO) != 0;
    bool zero = zero_allowed && value == 0.0;
    float width = ImGui::CalcItemWidth();
    if (zero_allowed) {
        if (ImGui::Checkbox("##zero", &zero))
            changed = param_store(v, t, p, zero ? 0.0 : param_nonzero(p));
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("%s 0: %s", p->key, p->zero_doc);
        ImGui::SameLine();
        width -= ImGui::GetItemRectSize().x + ImGui::GetStyle().ItemInnerSpacing.x;
    }
    ImGui::SetNextItemWidth(std::max(width, 40.0f));
    ImGui::BeginDisabled(zero);
    const double shown = zero ? param_nonzero(p) : value;
    const char *zero_text = p->zero_name ? p->zero_name : p->zero_doc;
    if (p->allowed) {
        char preview[64];
        std::snprintf(preview, sizeof preview, "%g", shown);
        if (ImGui::BeginCombo(p->key, zero ? zero_text : preview)) {
            for (uint32_t i = 0; i < p->allowed_count; ++i) {
                char item[40];
                std::snprintf(item, sizeof item, "%g", p->allowed[i]);
                if (ImGui::Selectable(item, value == p->allowed[i]))
                    changed = param_store(v, t, p, p->allowed[i]);
            }
            ImGui::EndCombo();
        }
    } else {
        double lo, hi;
        param_bounds(p, &lo, &hi);
        // A range over orders of magnitude gets a logarithmic slider. A value typed in
        // (ctrl+click) is not clamped: the registry refuses one out of range and says why.
        ImGuiSliderFlags flags =
            lo > 0.0 && hi / lo >= 20.0 ? ImGuiSliderFlags_Logarithmic : ImGuiSliderFlags_None;
        bool edited;
        if (p->type == UMBRA_PARAM_FLOAT) {
            float f = (float)shown;
            edited = ImGui::SliderFloat(p->key, &f, (float)lo, (float)hi,
                                        zero ? zero_text : "%.3g", flags);
            if (edited)
                changed = param_store(v, t, p, f);
        } else {
            uint32_t u = (uint32_t)shown, ulo = (uint32_t)lo, uhi = (uint32_t)hi;
            edited = hi - lo > 1e6 ? ImGui::InputScalar(p->key, ImGuiDataType_U32, &u)
                                   : ImGui::SliderScalar(p->key, ImGuiDataType_U32, &u, &ulo,
                                                         &uhi, zero ? zero_text : "%u", flags);
            if (edited)
                changed = param_store(v, t, p, u);
        }
    }
    ImGui::EndDisabled();
    tooltip(p);
    ImGui::PopID();
    return changed;
}

void section_status(viewer *v)
{
    const umbra_render_stats &s = v->stats;
    const view_frame_times &t = v->times;
    ImGui::Text("frame %.1f ms (umbra %.1f ms)", t.frame_ms, t.umbra_ms);
    ImGui::Text("upload %.1f ms, draw %.1f ms", t.upload_ms, t.draw_ms);
    ImGui::Text("shadow build %.2f ms, %s", s.shadow_build_ms,
                s.shadow_rebuilt ? "rebuilt" : "reused");
    ImGui::Text("render %.2f ms, %.2f M samples", s.render_ms, (double)s.samples * 1e-6);
    ImGui::TextDisabled("(timing: build %s, render %s)", timing_name(s.shadow_build_timing),
                        timing_name(s.render_timing));
    ImGui::Text("shadow memory %.2f MiB", (double)s.shadow_memory_bytes / 1048576.0);
    if (s.map_size)
        ImGui::Text("map %u x %u", s.map_size, s.map_size);
    if (s.slices)
        ImGui::Text("slices %u", s.slices);
    ImGui::Text("light channels %u", s.light_channels);
    ImGui::Text("shadows: %s", v->draft ? "draft, refined when the motion stops" : "full");
    if (v->message[0]) {
        ImGui::PushTextWrapPos(0.0f);
        if (v->message_is_error)
            ImGui::TextColored(ImVec4(1.0f, 0.45f, 0.35f, 1.0f), "%s", v->message);
        else
            ImGui::TextUnformatted(v->message);
        ImGui::PopTextWrapPos();
    }
}

void section_technique(viewer *v)
{
    umbra_shadow_desc *d = &v->s.shadow;
    const umbra_technique_info *current = umbra_technique_find_id(d->technique);
    if (ImGui::BeginCombo("technique", current ? current->name : "?")) {
        for (uint32_t i = 0; i < umbra_technique_count(); ++i) {
            const umbra_technique_info *t = umbra_technique_get(i);
            if (ImGui::Selectable(t->name, t == current)) {
                d->technique = t->id;
                v->changed |= VIEW_CHANGED_SHADOW;
            }
            if (ImGui::IsItemHovered())
                ImGui::SetTooltip("%s: %s\n\n%s", t->name, t->title, t->doc);
        }
        ImGui::EndCombo();
    }
    if (!current)
        return;
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextDisabled("%s", current->title);
    ImGui::PopTextWrapPos();
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("%s", current->doc);
    for (uint32_t k = 0; k < current->param_count; ++k)
        if (param_control(v, current, umbra_technique_param_get(current, k)))
            v->changed |= VIEW_CHANGED_SHADOW;
    if (current->param_count && ImGui::Button("defaults")) {
        for (uint32_t k = 0; k < current->param_count; ++k) {
            const umbra_param_info *p = umbra_technique_param_get(current, k);
            param_store(v, current, p, p->default_value);
        }
        v->changed |= VIEW_CHANGED_SHADOW;
    }
}

void section_light(viewer *v)
{
    umbra_light *l = &v->s.light;
    int type = l->type;
    // | rather than ||: both buttons are drawn in every frame.
    if (ImGui::RadioButton("directional", &type, UMBRA_LIGHT_DIRECTIONAL) |
        ImGui::RadioButton("point", &type, UMBRA_LIGHT_POINT))
        viewer_light_set_type(v, (umbra_light_type)type);
    ImGui::SameLine();
    ImGui::TextDisabled("(right drag)");
    if (ImGui::ColorEdit3("colour", l->color, ImGuiColorEditFlags_Float | ImGuiColorEditFlags_HDR))
        v->changed |= VIEW_CHANGED_LIGHT;
    float ambient = v->s.options.ambient[0];
    if (ImGui::SliderFloat("ambient", &ambient, 0.0f, 1.0f, "%.2f")) {
        v->s.options.ambient[0] = v->s.options.ambient[1] = v->s.options.ambient[2] = ambient;
        v->changed |= VIEW_CHANGED_OPTIONS;
    }
}

void section_render(viewer *v)
{
    umbra_render_desc *o = &v->s.options;
    bool shading = o->shading, ground = o->ground_plane;
    bool colored = o->transmission == UMBRA_TRANSMISSION_COLORED;
    if (ImGui::Checkbox("shading", &shading)) {
        o->shading = shading;
        v->changed |= VIEW_CHANGED_OPTIONS;
    }
    ImGui::SameLine();
    if (ImGui::Checkbox("ground", &ground)) {
        o->ground_plane = ground;
        v->changed |= VIEW_CHANGED_OPTIONS;
    }
    ImGui::SameLine();
    if (ImGui::Checkbox("coloured", &colored)) {
        o->transmission = colored ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
        v->changed |= VIEW_CHANGED_OPTIONS;
    }
    bool preintegrated = o->preintegrated;
    if (ImGui::Checkbox("pre-integrated", &preintegrated)) {
        o->preintegrated = preintegrated;
        v->changed |= VIEW_CHANGED_OPTIONS;
    }
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("pre-integrated segments along the view ray (and the convolution "
                          "technique's light)");
    bool progressive = o->interaction == UMBRA_INTERACTION_AUTO;
    if (ImGui::Checkbox("progressive shadows", &progressive)) {
        o->interaction = progressive ? UMBRA_INTERACTION_AUTO : UMBRA_INTERACTION_OFF;
        v->changed |= VIEW_CHANGED_OPTIONS;
    }
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("interaction auto: the technique's draft while the light or a shadow "
                          "setting changes, the full structure once it stops");
    if (ImGui::SliderFloat("step", &o->step, 0.05f, 4.0f, "%.3g voxels",
                           ImGuiSliderFlags_Logarithmic))
        v->changed |= VIEW_CHANGED_OPTIONS;
    // The projection modes draw no light: they take technique none (the library says so).
    static const char *const modes[] = {"composite", "mip", "minip", "average"};
    int mode = (int)o->mode;
    if (ImGui::Combo("mode", &mode, modes, 4)) {
        o->mode = (umbra_render_mode)mode;
        v->changed |= VIEW_CHANGED_OPTIONS;
    }
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("maximum, minimum and average intensity projection draw no light: "
                          "choose technique none with them");
}

// Clipping: one plane (its normal and its distance from the volume's centre) and the crop box,
// as fractions of the volume along each axis. Both apply to the light as to the view.
void section_clip(viewer *v)
{
    umbra_clip_desc *c = &v->s.clip;
    umbra_volume_info info;
    if (umbra_volume_get_info(v->s.view_volume, &info) != UMBRA_SUCCESS)
        return;
    bool plane = c->plane_count > 0;
    if (ImGui::Checkbox("clip plane", &plane)) {
        c->plane_count = plane ? 1 : 0;
        if (plane && c->planes[0][0] == 0.0f && c->planes[0][1] == 0.0f &&
            c->planes[0][2] == 0.0f) {
            c->planes[0][0] = -1.0f; // keeps x <= centre: the near half from the default view
            c->planes[0][3] = info.center[0];
        }
        v->changed |= VIEW_CHANGED_CLIP;
    }
    if (plane) {
        float *p = c->planes[0];
        if (ImGui::SliderFloat3("normal", p, -1.0f, 1.0f, "%.2f")) {
            if (p[0] == 0.0f && p[1] == 0.0f && p[2] == 0.0f)
                p[1] = 1e-3f; // the library refuses a zero normal
            v->changed |= VIEW_CHANGED_CLIP;
        }
        // d such that the plane passes at `offset` from the centre along the normal.
        const float n = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        const float dc = p[0] * info.center[0] + p[1] * info.center[1] + p[2] * info.center[2];
        float offset = (p[3] + dc) / n;
        if (ImGui::SliderFloat("offset", &offset, -0.5f * v->diagonal, 0.5f * v->diagonal,
                               "%.3g")) {
            p[3] = offset * n - dc;
            v->changed |= VIEW_CHANGED_CLIP;
        }
    }
    bool crop = c->crop != 0;
    if (ImGui::Checkbox("crop box", &crop)) {
        c->crop = crop;
        if (crop && c->crop_min[0] == 0.0f && c->crop_max[0] == 0.0f)
            for (int a = 0; a < 3; ++a) {
                c->crop_min[a] = -0.5f;
                c->crop_max[a] = (float)info.dims[a] - 0.5f;
            }
        v->changed |= VIEW_CHANGED_CLIP;
    }
    if (crop) {
        static const char *const names[3] = {"x", "y", "z"};
        for (int a = 0; a < 3; ++a) {
            const float hi = (float)info.dims[a] - 0.5f;
            if (ImGui::DragFloatRange2(names[a], &c->crop_min[a], &c->crop_max[a], 0.25f, -0.5f,
                                       hi, "%.1f", "%.1f", ImGuiSliderFlags_AlwaysClamp))
                v->changed |= VIEW_CHANGED_CLIP;
        }
    }
}

// The opacity curve: the table's alpha over its entries, filled with each entry's colour. A drag
// paints the opacity under the cursor (between the last position and this one, linearly), up to
// tf_curve_top at the top edge. Returns true when the table changed.
bool tf_curve(viewer *v)
{
    const float width = std::max(ImGui::GetContentRegionAvail().x, 64.0f), height = 110.0f;
    const ImVec2 p0 = ImGui::GetCursorScreenPos();
    ImGui::InvisibleButton("opacity", ImVec2(width, height));
    const uint32_t n = v->tf_count;
    const float top = v->tf_curve_top;
    float *t = v->tf_rgba;
    bool edited = false;
    if (ImGui::IsItemActive() && n >= 2) {
        const ImGuiIO &io = ImGui::GetIO();
        ImVec2 a = io.MousePos, b(io.MousePos.x - io.MouseDelta.x, io.MousePos.y - io.MouseDelta.y);
        if (ImGui::IsItemActivated())
            b = a;
        auto entry = [&](float x) {
            return std::clamp((x - p0.x) / width, 0.0f, 1.0f) * (float)(n - 1);
        };
        auto opacity = [&](float y) {
            return std::clamp((p0.y + height - y) / height, 0.0f, 1.0f) * top;
        };
        float ea = entry(a.x), eb = entry(b.x), oa = opacity(a.y), ob = opacity(b.y);
        if (ea > eb) {
            std::swap(ea, eb);
            std::swap(oa, ob);
        }
        uint32_t i0 = (uint32_t)std::lround(ea), i1 = (uint32_t)std::lround(eb);
        for (uint32_t i = i0; i <= i1; ++i) {
            float f = i1 > i0 ? (float)(i - i0) / (float)(i1 - i0) : 0.0f;
            t[4 * i + 3] = oa + f * (ob - oa);
        }
        edited = true;
    }
    ImDrawList *dl = ImGui::GetWindowDrawList();
    const ImVec2 p1(p0.x + width, p0.y + height);
    dl->AddRectFilled(p0, p1, IM_COL32(25, 25, 28, 255));
    ImVec2 prev;
    for (int x = 0; x < (int)width; ++x) {
        uint32_t i = (uint32_t)std::lround((double)x / (width - 1.0f) * (n - 1));
        const float *e = t + 4 * i;
        float y = p1.y - std::min(e[3] / top, 1.0f) * height;
        ImU32 c = IM_COL32((int)(255 * std::clamp(e[0], 0.0f, 1.0f)),
                           (int)(255 * std::clamp(e[1], 0.0f, 1.0f)),
                           (int)(255 * std::clamp(e[2], 0.0f, 1.0f)), 200);
        dl->AddLine(ImVec2(p0.x + x + 0.5f, p1.y), ImVec2(p0.x + x + 0.5f, y), c);
        ImVec2 here(p0.x + x + 0.5f, y);
        if (x > 0)
            dl->AddLine(prev, here, IM_COL32(255, 255, 255, 255), 1.5f);
        prev = here;
    }
    dl->AddRect(p0, p1, IM_COL32(110, 110, 120, 255));
    return edited;
}

void section_tf(viewer *v)
{
    const char *current = v->preset < 0 ? "(the volume's own)" : base_name(v->presets[v->preset]);
    if (ImGui::BeginCombo("preset", current)) {
        if (ImGui::Selectable("(the volume's own)", v->preset < 0))
            viewer_tf_load(v, -1);
        for (unsigned i = 0; i < v->n_presets; ++i)
            if (ImGui::Selectable(base_name(v->presets[i]), (int)i == v->preset))
                viewer_tf_load(v, (int)i);
        ImGui::EndCombo();
    }
    if (tf_curve(v))
        viewer_tf_commit(v);
    ImGui::SliderFloat("curve top", &v->tf_curve_top, 0.01f, 1.0f, "opacity %.3g",
                       ImGuiSliderFlags_Logarithmic);
    if (v->tf_has_range)
        ImGui::Text("%u entries over data values %g..%g", v->tf_count, v->tf_range[0],
                    v->tf_range[1]);
    else
        ImGui::Text("%u entries over the volume's range", v->tf_count);
    if (ImGui::Button("reset"))
        viewer_tf_load(v, v->preset);
    if (v->s.light_tf)
        ImGui::TextDisabled("(the light pass keeps --light-tf)");
}

void draw_panel(viewer *v)
{
    const ImGuiIO &io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(
        ImVec2(std::min(std::max(0.4f * io.DisplaySize.x, 240.0f), 320.0f), io.DisplaySize.y),
        ImGuiCond_FirstUseEver);
    if (ImGui::Begin("umbra-view")) {
        ImGui::PushItemWidth(-110.0f); // room for the labels on the right
        ImGui::PushTextWrapPos(0.0f);
        ImGui::TextDisabled("%s", umbra_context_device_name(v->s.ctx));
        ImGui::PopTextWrapPos();
        if (ImGui::CollapsingHeader("frame", ImGuiTreeNodeFlags_DefaultOpen))
            section_status(v);
        if (ImGui::CollapsingHeader("shadow technique", ImGuiTreeNodeFlags_DefaultOpen))
            section_technique(v);
        if (ImGui::CollapsingHeader("light", ImGuiTreeNodeFlags_DefaultOpen))
            section_light(v);
        if (ImGui::CollapsingHeader("rendering", ImGuiTreeNodeFlags_DefaultOpen))
            section_render(v);
        if (ImGui::CollapsingHeader("clipping"))
            section_clip(v);
        if (ImGui::CollapsingHeader("transfer function", ImGuiTreeNodeFlags_DefaultOpen))
            section_tf(v);
        if (ImGui::CollapsingHeader("keys and mouse"))
            ImGui::TextUnformatted("left drag: orbit    middle / shift+left: pan\n"
                                   "wheel: zoom    right / ctrl+left: light\n"
                                   "S: save frame to --out    G, Tab: panel\n"
                                   "P: print view options    R: reset view\n"
                                   "Esc: quit");
        ImGui::PopItemWidth();
    }
    // The rectangle in framebuffer pixels, for a snapshot taken with the panel shown.
    ImVec2 pos = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
    ImVec2 scale = io.DisplayFramebufferScale;
    v->panel[0] = (int)std::floor(pos.x * scale.x);
    v->panel[1] = (int)std::floor(pos.y * scale.y);
    v->panel[2] = (int)std::ceil((pos.x + size.x) * scale.x) - v->panel[0];
    v->panel[3] = (int)std::ceil((pos.y + size.y) * scale.y) - v->panel[1];
    ImGui::End();
}

} // namespace

int panel_init(viewer *v)
{
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO &io = ImGui::GetIO();
    io.IniFilename = nullptr;                   // no imgui.ini written into the working directory
    io.ConfigWindowsMoveFromTitleBarOnly = true; // a drag beside a control does not move the panel
    ImGui::StyleColorsDark();
    if (!ImGui_ImplGlfw_InitForOpenGL(v->window, true))
        return -1;
    if (!ImGui_ImplOpenGL3_Init(nullptr)) {
        ImGui_ImplGlfw_Shutdown();
        return -1;
    }
    return 0;
}

void panel_shutdown(void)
{
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
}

void panel_frame(viewer *v)
{
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    std::memset(v->panel, 0, sizeof v->panel);
    if (v->show_panel)
        draw_panel(v);
}

void panel_draw(viewer *v)
{
    if (v->have_frame)
        ImGui::GetBackgroundDrawList()->AddImage(
            reinterpret_cast<ImTextureID>(static_cast<intptr_t>(v->pr.texture)), ImVec2(0, 0),
            ImGui::GetIO().DisplaySize);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

int panel_wants_mouse(void)
{
    return ImGui::GetIO().WantCaptureMouse;
}

int panel_wants_keyboard(void)
{
    // An open combo or popup takes Esc to close it, not to quit.
    return ImGui::GetIO().WantCaptureKeyboard ||
           ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId);
}
