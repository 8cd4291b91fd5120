// SPDX-License-Identifier: Apache-2.0
/* umbra/umbra.h: the whole public API of umbra, an OpenCL library for shadows in direct volume
 * rendering. Include this, or the one header per concept it lists. The optional file layer
 * (umbra_io: NRRD, .dat, raw, transfer-function files, PNG/EXR) has its own header, umbra/io.h. */
#ifndef UMBRA_UMBRA_H
#define UMBRA_UMBRA_H

#include "umbra/error.h"
#include "umbra/context.h"
#include "umbra/volume.h"
#include "umbra/transfer_function.h"
#include "umbra/renderer.h"
#include "umbra/registry.h"
#include "umbra/scene.h"
#include "umbra/part.h"

#endif
