//! Submitting work to the context's queue: one-shot uploads, frame submissions with their
//! semaphores and fence.

use std::sync::Arc;

use ash::vk;

use super::command::{CommandBuffer, CommandRecorder};
use super::context::Context;
use super::sync::{Fence, Semaphore};
use super::{GpuResult, VkContext};

impl Context {
    /// Record commands with `record`, submit them and wait for completion (uploads).
    pub fn submit_and_wait<R>(
        self: &Arc<Self>,
        record: impl FnOnce(&mut CommandRecorder) -> R,
    ) -> GpuResult<R> {
        let mut cmd = CommandBuffer::new(self, "one-shot")?;
        let fence = Fence::new(self, false)?;
        let out = {
            let mut rec = cmd.begin()?;
            record(&mut rec)
        };
        cmd.end()?;
        self.submit(&cmd, &fence)?;
        fence.wait()?;
        Ok(out)
    }

    /// Submit `cmd` to the queue; `fence` is signalled when it completes.
    pub fn submit(&self, cmd: &CommandBuffer, fence: &Fence) -> GpuResult<()> {
        self.submit_with(cmd, fence, None, None)
    }

    /// Submit `cmd`, first waiting for `wait` (before colour output and transfers) and
    /// signalling `signal` when done; `fence` is signalled when it completes.
    pub fn submit_with(
        &self,
        cmd: &CommandBuffer,
        fence: &Fence,
        wait: Option<&Semaphore>,
        signal: Option<&Semaphore>,
    ) -> GpuResult<()> {
        let cmds = [cmd.raw()];
        let waits: Vec<vk::Semaphore> = wait.iter().map(|s| s.raw()).collect();
        let stages = vec![
            vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                | vk::PipelineStageFlags::TRANSFER;
            waits.len()
        ];
        let signals: Vec<vk::Semaphore> = signal.iter().map(|s| s.raw()).collect();
        let submit = [vk::SubmitInfo::default()
            .command_buffers(&cmds)
            .wait_semaphores(&waits)
            .wait_dst_stage_mask(&stages)
            .signal_semaphores(&signals)];
        // SAFETY: the command buffer finished recording; the fence is unsignalled; the
        // semaphores are owned by the caller and alive until the submission completes.
        unsafe { self.device.queue_submit(self.queue(), &submit, fence.raw()) }.ctx("queue submit")
    }
}
