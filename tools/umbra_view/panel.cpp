// SPDX-License-Identifier: Apache-2.0
// tools/umbra_view/panel.cpp: umbra-view's panel, Dear ImGui with Debian's GLFW and OpenGL 3
// backends (libimgui-dev builds both into libimgui.a). The frame itself is drawn as the first
// thing of the GUI's draw list, 1:1 from the texture present.c filled; the panel then goes over
// it. The technique section walks the table of techniques_panel.h and names no technique or
// parameter itself. Everything it edits goes into the viewer's copies of the settings and marks
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

#include "techniques_panel.h"
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

void tooltip(const view_param *p)
{
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("%s: %s (default %g)", p->name, p->doc, view_param_default(p));
}

// One control for parameter p of d, by its kind and range; true when the user changed it.
bool param_control(umbra_shadow_desc *d, const view_param *p)
{
    double value = view_param_get(d, p);
    bool changed = false;
    ImGui::PushID(p->name);
    if (p->kind == VIEW_PARAM_BOOL) {
        bool b = value != 0.0;
        if ((changed = ImGui::Checkbox(p->name, &b)))
            view_param_set(d, p, b ? 1.0 : 0.0);
        tooltip(p);
    } else if (p->choices) {
        char preview[32];
        std::snprintf(preview, sizeof preview, "%g", value);
        if (ImGui::BeginCombo(p->name, preview)) {
            for (unsigned i = 0; i < p->n_choices; ++i) {
                char item[32];
                std::snprintf(item, sizeof item, "%u", p->choices[i]);
                if (ImGui::Selectable(item, value == p->choices[i])) {
                    view_param_set(d, p, p->choices[i]);
                    changed = true;
                }
            }
            ImGui::EndCombo();
        }
        tooltip(p);
    } else {
        // A parameter whose 0 means "auto" (or the like) gets a checkbox for that in front of
        // its slider; the slider then shows the word and is disabled.
        bool zero = p->zero && value == 0.0;
        float width = ImGui::CalcItemWidth();
        if (p->zero) {
            if (ImGui::Checkbox("##zero", &zero)) {
                view_param_set(d, p, zero ? 0.0 : p->nonzero);
                changed = true;
            }
            if (ImGui::IsItemHovered())
                ImGui::SetTooltip("%s: %s", p->name, p->zero);
            ImGui::SameLine();
            width -= ImGui::GetItemRectSize().x + ImGui::GetStyle().ItemInnerSpacing.x;
        }
        ImGui::SetNextItemWidth(std::max(width, 40.0f));
        ImGui::BeginDisabled(zero);
        ImGuiSliderFlags flags = p->logarithmic ? ImGuiSliderFlags_Logarithmic : 0;
        bool edited;
        if (p->kind == VIEW_PARAM_FLOAT) {
            float f = zero ? (float)p->nonzero : (float)view_param_get(d, p);
            edited = ImGui::SliderFloat(p->name, &f, (float)p->min, (float)p->max,
                                        zero ? p->zero : "%.3g", flags);
            if (edited)
                view_param_set(d, p, f);
        } else {
            uint32_t u = zero ? (uint32_t)p->nonzero : (uint32_t)view_param_get(d, p);
            uint32_t lo = (uint32_t)p->min, hi = (uint32_t)p->max;
            edited = p->max - p->min > 1e6
                         ? ImGui::InputScalar(p->name, ImGuiDataType_U32, &u)
                         : ImGui::SliderScalar(p->name, ImGuiDataType_U32, &u, &lo, &hi,
                                               zero ? p->zero : "%u", flags);
            if (edited)
                view_param_set(d, p, u);
        }
        ImGui::EndDisabled();
        tooltip(p);
        changed = changed || edited;
    }
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
        ImGui::Text("map %u x %u%s", s.map_size, s.map_size,
                    v->s.shadow.map_size == UMBRA_MAP_SIZE_AUTO ? " (auto)" : "");
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
    if (ImGui::BeginCombo("technique", umbra_shadow_technique_name(d->technique))) {
        for (unsigned i = 0; i < view_technique_count(); ++i) {
            umbra_shadow_technique t = view_technique_at(i);
            if (ImGui::Selectable(umbra_shadow_technique_name(t), t == d->technique)) {
                d->technique = t;
                v->changed |= VIEW_CHANGED_SHADOW;
            }
        }
        ImGui::EndCombo();
    }
    unsigned n = 0;
    const view_param *const *params = view_technique_params(d->technique, &n);
    for (unsigned i = 0; i < n; ++i)
        if (param_control(d, params[i]))
            v->changed |= VIEW_CHANGED_SHADOW;
    if (n && ImGui::Button("defaults")) {
        for (unsigned i = 0; i < n; ++i)
            view_param_set(d, params[i], view_param_default(params[i]));
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
    if (ImGui::SliderFloat("step", &o->step, 0.05f, 4.0f, "%.3g voxels",
                           ImGuiSliderFlags_Logarithmic))
        v->changed |= VIEW_CHANGED_OPTIONS;
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
