//! Copies of device memory to the host, for the inspection hooks of tests and tools and the
//! volume tier's reads: a host-readable buffer, and a device buffer's first bytes through one
//! frame graph (no hand barriers).

use ash::vk;

use super::graph::FrameGraph;
use crate::vk::{Access, Buffer, BufferDesc, GpuResult};

/// A host-readable buffer of `bytes` named `name`.
pub fn readback(
    ctx: &std::sync::Arc<crate::vk::Context>,
    name: &str,
    bytes: u64,
) -> GpuResult<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc::new(name, bytes, vk::BufferUsageFlags::TRANSFER_DST).readback(),
    )
}

/// The first `bytes` of device-local `buffer` (it needs `TRANSFER_SRC` usage), copied to the
/// host; the caller has waited for the frames that write it.
pub fn read_device_buffer(
    ctx: &std::sync::Arc<crate::vk::Context>,
    buffer: &Buffer,
    bytes: u64,
) -> GpuResult<Vec<u8>> {
    let bytes = bytes.min(buffer.size);
    let mut out = readback(ctx, "buffer readback", bytes)?;
    ctx.submit_and_wait(|rec| {
        let mut g = FrameGraph::new(false);
        let src = g.import_buffer("read buffer", buffer);
        let dst = g.import_buffer("buffer readback", &out);
        g.pass("copy buffer")
            .read(src, Access::TransferRead)
            .discard(dst, Access::TransferWrite)
            .record(|rec, _| {
                rec.copy_buffer(buffer, 0, &out, 0, bytes);
                Ok(())
            });
        g.pass("host reads").read(dst, Access::HostRead).done();
        g.run_untimed(rec).map(|_| ())
    })??;
    out.read()
}
