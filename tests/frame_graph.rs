//! The frame graph's transient resources on a real device: created from their descriptions
//! with the contents the passes write, reused by the next frame, grown by half again,
//! shrunk after long disuse of their size, images recreated when their description changes,
//! replaced objects handed back for deferred release, the next frame waiting for the last
//! frame's uses of a buffer only, and a transient read before any pass of the frame wrote it
//! refused.

mod common;

use std::sync::Arc;

use ash::vk;
use hairmesh::render::graph::{
    FrameGraph, SHRINK_AFTER_FRAMES, TransientBuffer, TransientPool, UserTerms,
};
use hairmesh::vk::{Access, Buffer, BufferDesc, Context, ImageDesc, Profiler};

use common::{assert_no_validation_errors, context};

const FILL: u32 = 0x5eed_cafe;

fn scratch(bytes: u64) -> TransientBuffer {
    TransientBuffer {
        name: "scratch",
        bytes,
        usage: vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::TRANSFER_DST
            | vk::BufferUsageFlags::TRANSFER_SRC,
        binding: None,
        user_terms: UserTerms::FRAME_STORAGE,
    }
}

/// One frame: fill a transient of `bytes` (after a read of it, with `read_first`), copy
/// its first 16 bytes out, and a transient image of `side` cleared by a transition. Returns
/// the description and the 16 bytes read back.
fn frame(
    ctx: &Arc<Context>,
    pool: &mut TransientPool,
    bytes: u64,
    side: u32,
    read_first: bool,
) -> Result<(String, Vec<u32>), String> {
    let mut profiler = Profiler::new(ctx).unwrap();
    let mut out = Buffer::new(
        ctx,
        &BufferDesc::new("readback", 16, vk::BufferUsageFlags::TRANSFER_DST).readback(),
    )
    .unwrap();
    let desc = ctx
        .submit_and_wait(|rec| {
            profiler.reset(rec);
            let mut g = FrameGraph::new(true);
            let b = g.create_buffer(scratch(bytes));
            let image_desc = ImageDesc::new_2d("layer", vk::Format::R8G8B8A8_UNORM, side, side)
                .usage(vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_DST);
            let image = g.create_image("layer", image_desc);
            let dst = g.import_buffer("readback", &out);
            if read_first {
                g.pass("early reader").read(b, Access::ComputeRead).done();
            }
            g.pass("fill")
                .discard(b, Access::TransferWrite)
                .discard(image, Access::TransferWrite)
                .record(move |rec, res| {
                    rec.fill_buffer(res.buffer(b)?, 0, bytes, FILL);
                    Ok(())
                });
            let out = &out;
            g.pass("copy out")
                .read(b, Access::TransferRead)
                .discard(dst, Access::TransferWrite)
                .record(move |rec, res| {
                    rec.copy_buffer(res.buffer(b)?, 0, out, 0, 16);
                    Ok(())
                });
            g.pass("host reads").read(dst, Access::HostRead).done();
            g.run(rec, &mut profiler, pool)
        })
        .unwrap();
    let desc = desc.map_err(|e| e.to_string())?.unwrap();
    let words = bytemuck::pod_collect_to_vec(&out.read().unwrap());
    Ok((desc, words))
}

/// The lines of pass `name` in a description (its header to the next pass).
fn pass(desc: &str, name: &str) -> String {
    let mut lines = desc
        .lines()
        .skip_while(|l| !l.ends_with(&format!(". {name}")));
    let head = lines
        .next()
        .unwrap_or_else(|| panic!("no pass {name} in\n{desc}"));
    let body: Vec<&str> = lines.take_while(|l| l.starts_with("       ")).collect();
    format!("{head}\n{}", body.join("\n"))
}

fn line<'a>(desc: &'a str, name: &str) -> &'a str {
    desc.lines()
        .find(|l| l.trim_start().starts_with(&format!("{name}:")))
        .unwrap_or_else(|| panic!("no {name} line in\n{desc}"))
}

#[test]
fn transients_are_created_reused_grown_and_shrunk() {
    let ctx = context();
    let mut pool = TransientPool::new(&ctx);
    let (d, words) = frame(&ctx, &mut pool, 1024, 8, false).unwrap();
    assert_eq!(words, vec![FILL; 4], "the passes wrote the created buffer");
    assert!(
        line(&d, "scratch").contains("1024 bytes (1024 needed, new)"),
        "{d}"
    );
    assert!(line(&d, "layer").contains("new"), "{d}");
    assert!(
        !pass(&d, "fill").contains("barrier: scratch"),
        "a new buffer waits for nothing before its first write:\n{d}"
    );
    let held = pool.bytes();
    assert_eq!(held, 1024 + 8 * 8 * 4);
    assert!(pool.take_released().is_empty());

    // The next frame reuses both, with the image's layout known from the last frame.
    let (d, _) = frame(&ctx, &mut pool, 1024, 8, false).unwrap();
    assert!(line(&d, "scratch").contains("(1024 needed, reused)"), "{d}");
    // Its first use waits for the last frame's uses of it, not for any use.
    assert!(
        pass(&d, "fill").contains("barrier: scratch [TransferRead|TransferWrite] -> TransferWrite"),
        "{d}"
    );
    assert!(line(&d, "layer").contains("reused"), "{d}");
    assert_eq!(pool.bytes(), held);

    // More than it holds: grown to the need, or by half again when that is more.
    let (d, words) = frame(&ctx, &mut pool, 1100, 8, false).unwrap();
    assert!(
        line(&d, "scratch").contains("1536 bytes (1100 needed, grown from 1024)"),
        "{d}"
    );
    assert_eq!(words, vec![FILL; 4]);
    assert_eq!(
        pool.take_released().len(),
        1,
        "the old buffer goes to deferred release"
    );
    let (d, _) = frame(&ctx, &mut pool, 4096, 16, false).unwrap();
    assert!(
        line(&d, "scratch").contains("4096 bytes (4096 needed, grown from 1536)"),
        "{d}"
    );
    assert!(line(&d, "layer").contains("recreated"), "{d}");
    assert_eq!(pool.take_released().len(), 2);

    // Needing under a quarter of it: kept, until that has lasted SHRINK_AFTER_FRAMES frames.
    for n in 1..SHRINK_AFTER_FRAMES {
        let (d, _) = frame(&ctx, &mut pool, 64, 16, false).unwrap();
        assert!(line(&d, "scratch").contains("reused"), "frame {n}: {d}");
    }
    let (d, words) = frame(&ctx, &mut pool, 64, 16, false).unwrap();
    assert!(
        line(&d, "scratch").contains("64 bytes (64 needed, shrunk from 4096)"),
        "{d}"
    );
    assert_eq!(words, vec![FILL; 4]);
    assert_eq!(pool.take_released().len(), 1);
    assert_no_validation_errors(&ctx);
}

#[test]
fn reading_a_transient_before_it_is_written_is_refused() {
    let ctx = context();
    let mut pool = TransientPool::new(&ctx);
    let err = frame(&ctx, &mut pool, 256, 4, true).unwrap_err();
    assert!(
        err.contains("pass early reader reads scratch, which no earlier pass of the frame wrote"),
        "{err}"
    );
    // The pool is still usable.
    frame(&ctx, &mut pool, 256, 4, false).unwrap();
    assert_no_validation_errors(&ctx);
}

#[test]
fn a_buffer_past_the_device_limit_is_refused_before_allocating() {
    let ctx = context();
    let pool = TransientPool::new(&ctx);
    let too_big = ctx.info.max_storage_buffer_range + 1;
    let err = pool.check(&scratch(too_big)).unwrap_err().to_string();
    // Named in the user's terms (what grows it, the flag that shrinks it) with the buffer.
    assert!(
        err.contains("(scratch) needs")
            && err.contains("largest storage buffer")
            && err.contains("--size"),
        "{err}"
    );
    assert_eq!(pool.bytes(), 0);
}
