// SPDX-License-Identifier: Apache-2.0
/* host/mpi/mpi_internal.h: what host/mpi/mpi.c shares with host/mpi/composite.c. */
#ifndef UMBRA_MPI_INTERNAL_H
#define UMBRA_MPI_INTERNAL_H

#include "umbra/mpi.h"

#define MSG UMBRA_MPI_MESSAGE_MAX

/* Records status and a formatted message on ctx (NULL: dropped) and returns status. */
umbra_status umbra__mpi_fail(umbra_context ctx, umbra_status status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Agrees st with ctx's last message as the local one. */
static inline umbra_status agree(MPI_Comm comm, umbra_context ctx, umbra_status st)
{
    return umbra_mpi_agree(comm, ctx, st, NULL, NULL, 0);
}

static inline double now_ms(void)
{
    return MPI_Wtime() * 1e3;
}

/* comm's ranks in view order for camera (part: this rank's part, placement: its volume's), as a
 * new communicator *ordered (the caller frees it), and *ordered_root, where rank root of comm
 * stands in it (-1 where root is not a rank of comm). Collective; every failure is agreed. */
umbra_status umbra__mpi_view_ordered(MPI_Comm comm, umbra_context ctx,
                                     const umbra_part_desc *part,
                                     const umbra_volume_info *placement,
                                     const umbra_camera *camera, int root, MPI_Comm *ordered,
                                     int *ordered_root);

#endif
