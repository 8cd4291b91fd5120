// SPDX-License-Identifier: Apache-2.0
// consumer.cpp: a C++ application that targets OpenCL 3.0, makes its own context and queue with
// clCreateCommandQueueWithProperties (a 2.0+ call), hands them to umbra, renders the built-in
// scene and writes it with umbra_io. Usage: consumer_cxx out.png
#include <CL/cl.h>
#include <umbra/io.h>

#include <cstdio>
#include <vector>

int main(int argc, char **argv)
{
    const char *out = argc > 1 ? argv[1] : "consumer.png";
    cl_platform_id platform = nullptr;
    cl_device_id device = nullptr;
    cl_uint n = 0;
    if (clGetPlatformIDs(1, &platform, &n) != CL_SUCCESS || n == 0 ||
        clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 1, &device, &n) != CL_SUCCESS || n == 0) {
        std::fprintf(stderr, "consumer_cxx: no OpenCL device\n");
        return 1;
    }
    cl_int err = CL_SUCCESS;
    cl_context cl_ctx = clCreateContext(nullptr, 1, &device, nullptr, nullptr, &err);
    const cl_queue_properties props[] = {0};
    cl_command_queue queue =
        err == CL_SUCCESS ? clCreateCommandQueueWithProperties(cl_ctx, device, props, &err)
                          : nullptr;
    if (err != CL_SUCCESS) {
        std::fprintf(stderr, "consumer_cxx: OpenCL set-up failed (%d)\n", static_cast<int>(err));
        return 1;
    }

    const uint32_t w = 96, h = 72;
    std::vector<float> rgba(static_cast<size_t>(w) * h * 4);
    umbra_context ctx = nullptr;
    umbra_scene scene{};
    umbra_renderer r = nullptr;
    umbra_shadow_desc shadow;
    umbra_shadow_desc_init(&shadow);
    shadow.technique = UMBRA_SHADOW_REFERENCE;

    umbra_status st = umbra_context_create_from_cl(cl_ctx, device, queue, nullptr, &ctx);
    if (!st) st = umbra_scene_create(ctx, "spheres", 48, &scene);
    if (!st) st = umbra_renderer_create(ctx, &r);
    if (!st) st = umbra_renderer_set_volume(r, scene.volume);
    if (!st) st = umbra_renderer_set_transfer_function(r, scene.tf);
    if (!st) st = umbra_renderer_set_camera(r, &scene.camera);
    if (!st) st = umbra_renderer_set_light(r, &scene.light);
    if (!st) st = umbra_renderer_set_options(r, &scene.options);
    if (!st) st = umbra_renderer_set_shadow(r, &shadow);
    if (!st) st = umbra_renderer_render(r, w, h, rgba.data());
    if (!st) st = umbra_image_write(ctx, out, w, h, rgba.data());
    if (st)
        std::fprintf(stderr, "consumer_cxx: %s: %s\n", umbra_status_to_string(st),
                     ctx ? umbra_context_last_message(ctx) : "no context");
    umbra_renderer_release(r);
    umbra_scene_release(&scene);
    umbra_context_release(ctx);
    clReleaseCommandQueue(queue);
    clReleaseContext(cl_ctx);
    if (!st)
        std::printf("umbra %s: wrote %s\n", umbra_version(), out);
    return st ? 1 : 0;
}
