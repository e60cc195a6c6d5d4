//! The renderer on a host's Vulkan device (issue 27's first step): a minimal host (this test,
//! playing an engine) creates its own instance with the validation layer, picks a device,
//! creates it with `vk::create_host_device` and hands it to `Context::from_host`. The
//! renderer draws the same image as on a device of its own, validation stays clean, and when
//! the renderer and its context are dropped the host's device is still alive: the host uses
//! it, then destroys it and its instance itself.
//!
//! The host code is raw `ash`, as an engine's would be; that is why this test has `unsafe`.

mod common;

use std::sync::Arc;

use common::host::Host;
use common::*;
use hairmesh::render::{Renderer, RendererDesc};
use hairmesh::vk::Context;

const SIZE: u32 = 96;

/// head_long drawn on the compute path at full detail on `ctx`.
fn draw(ctx: &Arc<Context>) -> Vec<u8> {
    let (baked, style) = sample("head_long.obj");
    let mut r = Renderer::new(ctx, &RendererDesc::default().size(SIZE, SIZE)).unwrap();
    upload(&mut r, &baked, &style, 16, 4);
    render(&mut r, &framing(&baked), &compute_full()).rgba
}

#[test]
fn the_renderer_draws_on_a_host_device_and_leaves_it_alive() {
    let own = draw(&context());
    let host = Host::new();
    {
        let ctx = Arc::new(Context::from_host(host.lend(false)).unwrap());
        let drawn = draw(&ctx);
        let bg = &drawn[..4];
        let covered = drawn.chunks(4).filter(|p| p != &bg).count();
        let diff = mean_abs_diff(&own, &drawn);
        println!("host device: {covered} hair pixels, mean difference to its own device {diff:e}");
        assert!(covered > 200, "only {covered} pixels drawn");
        // Measured 0 (the same driver draws the same pixels on either device).
        assert!(diff < 1e-5, "the host device's image differs by {diff}");
        assert_no_validation_errors(&ctx);
    }
    // The renderer and its context are gone; the host's device is not.
    host.still_works();
}
