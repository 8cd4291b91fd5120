/* umbra/umbra.h: the whole public API of umbra, an OpenCL library for shadows in direct volume
 * rendering. Include this, or the one header per concept it lists. */
#ifndef UMBRA_UMBRA_H
#define UMBRA_UMBRA_H

#include "umbra/error.h"
#include "umbra/context.h"
#include "umbra/volume.h"
#include "umbra/transfer_function.h"
#include "umbra/renderer.h"
#include "umbra/scene.h"
#include "umbra/image.h"

#define UMBRA_VERSION_MAJOR 0
#define UMBRA_VERSION_MINOR 1
#define UMBRA_VERSION_PATCH 0

#endif
