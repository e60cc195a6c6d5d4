//! The frame graph: every pass of a frame is added with the resources it reads and writes
//! and how ([`Access`] uses); the graph runs the passes in the order they were added and
//! derives every barrier and image layout transition from consecutive uses. Passes record
//! commands only; they never order themselves against each other.
//!
//! Resources are imported: buffers (their earlier uses, in earlier frames, are unknown, so
//! the first use waits for anything), images whose last use the owner keeps
//! ([`ImageState::Tracked`], written back when the frame is recorded) or that must be left
//! in one use ([`ImageState::Fixed`]: character textures stay sampled), swapchain images, and
//! host-written inputs that need no GPU ordering (declared so the frame can be printed).
//!
//! Transient buffers and images are created by the graph from their descriptions
//! ([`FrameGraph::create_buffer`], [`FrameGraph::create_image`]) when it runs, from a
//! [`TransientPool`] that reuses them across frames ([`transient`]); their contents do not
//! outlive the frame, so their first use must write them. Passes name any resource's object
//! at record time through [`PassResources`].
//!
//! Hazards, per resource: a read waits for the last writes unless it has already been made
//! visible to that use; a write waits for the last writes and every read since; an image
//! whose layout changes is transitioned (the transition counts as a write).

pub mod transient;

use std::fmt::Write as _;

use crate::vk::{
    Access, BarrierImage, Buffer, CommandRecorder, DescriptorSet, GpuError, GpuResult, Image,
    ImageBarrier, ImageDesc, Profiler, SwapchainImage,
};
pub use transient::{Realized, SHRINK_AFTER_FRAMES, TransientBuffer, TransientPool, UserTerms};

/// A resource of the frame graph.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Res(usize);

/// How an imported image's state is known.
pub enum ImageState<'a> {
    /// Its last use, kept by the owner across frames; the graph writes the frame's last use
    /// back when the frame is recorded.
    Tracked(&'a mut Access),
    /// Always in this use between frames (the graph returns it there at the end).
    Fixed(Access),
}

enum Object<'a> {
    /// Buffers are ordered with global memory dependencies.
    Buffer(&'a Buffer),
    /// A set of buffers that shaders reach by device address (no binding names them), ordered
    /// as one buffer: passes declare their uses of the whole set.
    AddressBuffers,
    Image(&'a Image),
    Swapchain(&'a SwapchainImage),
    /// Created when the graph runs.
    TransientBuffer(TransientBuffer),
    TransientImage(ImageDesc),
    /// Written by the host before the submission (visible to every use): never ordered.
    Host,
}

/// A small set of [`Access`] uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Uses(u32);

impl Uses {
    fn of(a: Access) -> Self {
        Uses(1 << a as u32)
    }
    fn contains(self, a: Access) -> bool {
        self.0 & (1 << a as u32) != 0
    }
    fn is_empty(self) -> bool {
        self.0 == 0
    }
    fn list(self) -> Vec<Access> {
        Access::ALL
            .iter()
            .copied()
            .filter(|a| self.contains(*a))
            .collect()
    }
    /// Every use a buffer can have (attachments, sampling and presentation are image uses):
    /// what an earlier frame may have done to a buffer.
    fn any_buffer_use() -> Self {
        let image_only = [
            Access::Nothing,
            Access::SampledRead,
            Access::ColorAttachment,
            Access::DepthAttachment,
            Access::Present,
        ];
        Uses(
            Access::ALL
                .iter()
                .filter(|a| !image_only.contains(a))
                .fold(0, |m, a| m | (1 << *a as u32)),
        )
    }
}

impl std::ops::BitOr for Uses {
    type Output = Uses;
    fn bitor(self, o: Uses) -> Uses {
        Uses(self.0 | o.0)
    }
}

/// What the graph knows of a resource while it runs.
struct Tracker {
    /// Uses the next access must wait for as writes (writes, and layout transitions).
    writes: Uses,
    /// Reads since those writes that have been made visible (no barrier needed again).
    visible: Uses,
    /// Reads since the last write (a write must wait for them).
    reads: Uses,
    /// The last use of an image (its layout).
    last: Access,
}

struct Resource<'a> {
    name: &'static str,
    object: Object<'a>,
    tracked: Option<&'a mut Access>,
    fixed: Option<Access>,
    tracker: Tracker,
    /// Used by a pass already this frame.
    touched: bool,
}

/// One declared use of a resource by a pass.
#[derive(Clone, Copy, Debug)]
struct Use {
    res: Res,
    access: Access,
    /// Written without reading the old contents (images transition from `UNDEFINED`).
    discard: bool,
}

type Record<'a> = Box<dyn FnOnce(&mut CommandRecorder, &PassResources) -> GpuResult<()> + 'a>;

/// A resource's object once the graph runs.
#[derive(Clone, Copy)]
enum Bound<'r> {
    None,
    Buffer(&'r Buffer),
    Image(&'r Image),
    Swapchain(&'r SwapchainImage),
}

/// The objects behind a running graph's resources, for the passes' commands.
pub struct PassResources<'r> {
    bound: Vec<Bound<'r>>,
    names: Vec<&'static str>,
}

impl PassResources<'_> {
    /// The buffer behind `res`.
    pub fn buffer(&self, res: Res) -> GpuResult<&Buffer> {
        match self.bound[res.0] {
            Bound::Buffer(b) => Ok(b),
            _ => Err(self.not(res, "a buffer")),
        }
    }

    /// The image behind `res`.
    pub fn image(&self, res: Res) -> GpuResult<&Image> {
        match self.bound[res.0] {
            Bound::Image(i) => Ok(i),
            _ => Err(self.not(res, "an image")),
        }
    }

    fn not(&self, res: Res, what: &str) -> GpuError {
        GpuError::Unsupported(format!("frame graph: {} is not {what}", self.names[res.0]))
    }
}

enum Node<'a> {
    Pass {
        name: &'static str,
        uses: Vec<Use>,
        record: Option<Record<'a>>,
    },
    BeginScope(&'static str),
    EndScope,
}

/// The name of the last barriers of a frame, which return fixed-state images to their use.
const RETURN_FIXED: &str = "(return fixed images)";

/// Open a scope named `name` where a profiler runs and no scope is open; whether it did.
fn open_own_scope(
    profiler: Option<&mut Profiler>,
    rec: &mut CommandRecorder,
    name: &'static str,
) -> bool {
    match profiler {
        Some(p) if !p.scope_open() => {
            p.begin(rec, name);
            true
        }
        _ => false,
    }
}

/// One frame's passes and resources; see the module documentation.
pub struct FrameGraph<'a> {
    resources: Vec<Resource<'a>>,
    nodes: Vec<Node<'a>>,
    /// A `(pass, resource, use)` to leave out (tests: show that sync validation catches it).
    omit: Option<(&'a str, &'a str, Option<Access>)>,
    describe: bool,
    /// Sets whose bindings the transient buffers are written to.
    bind_sets: Vec<&'a DescriptorSet>,
}

/// A pass being declared: its uses, then its commands.
pub struct PassBuilder<'g, 'a> {
    graph: &'g mut FrameGraph<'a>,
    name: &'static str,
    uses: Vec<Use>,
}

impl<'a> PassBuilder<'_, 'a> {
    fn add(mut self, res: Res, access: Access, discard: bool) -> Self {
        let omitted = self.graph.omit.is_some_and(|(p, r, a)| {
            p == self.name && r == self.graph.resources[res.0].name && a.is_none_or(|a| a == access)
        });
        if !omitted {
            self.uses.push(Use {
                res,
                access,
                discard,
            });
        }
        self
    }

    /// The pass reads `res` as `access` (a use that does not write).
    pub fn read(self, res: Res, access: Access) -> Self {
        debug_assert!(
            !access.writes(),
            "{access:?} writes: declare it with write()"
        );
        self.add(res, access, false)
    }

    /// The pass writes (and may read) `res` as `access`.
    pub fn write(self, res: Res, access: Access) -> Self {
        self.add(res, access, false)
    }

    /// The pass overwrites `res` as `access` without reading what was there (an image is
    /// transitioned from `UNDEFINED`).
    pub fn discard(self, res: Res, access: Access) -> Self {
        self.add(res, access, true)
    }

    /// [`Self::write`] of `res` where there is one (a resource only some frames have).
    pub fn write_some(self, res: Option<Res>, access: Access) -> Self {
        match res {
            Some(r) => self.write(r, access),
            None => self,
        }
    }

    /// [`Self::read`] of `res` where there is one.
    pub fn read_some(self, res: Option<Res>, access: Access) -> Self {
        match res {
            Some(r) => self.read(r, access),
            None => self,
        }
    }

    /// [`Self::read`] of every resource in `list`.
    pub fn read_all(self, list: &[Res], access: Access) -> Self {
        list.iter().fold(self, |p, r| p.read(*r, access))
    }

    /// Add the pass with the commands `record` writes (after the graph's barriers).
    pub fn record(
        self,
        record: impl FnOnce(&mut CommandRecorder, &PassResources) -> GpuResult<()> + 'a,
    ) {
        self.graph.nodes.push(Node::Pass {
            name: self.name,
            uses: self.uses,
            record: Some(Box::new(record)),
        });
    }

    /// Add the pass with no commands of its own: only its uses (a hand-over, such as the
    /// host reading back or the presentation engine taking the image).
    pub fn done(self) {
        self.graph.nodes.push(Node::Pass {
            name: self.name,
            uses: self.uses,
            record: None,
        });
    }
}

impl<'a> FrameGraph<'a> {
    /// An empty frame; `describe`: keep a printable account of passes, uses and barriers.
    pub fn new(describe: bool) -> Self {
        FrameGraph {
            resources: Vec::new(),
            nodes: Vec::new(),
            omit: None,
            describe,
            bind_sets: Vec::new(),
        }
    }

    /// Leave out pass `pass`'s declared use `access` of `resource` (`None`: every use; a
    /// deliberate bug, for the test that shows synchronization validation catches a missing
    /// declaration).
    pub fn omit_use(&mut self, pass: &'a str, resource: &'a str, access: Option<Access>) {
        self.omit = Some((pass, resource, access));
    }

    fn push(
        &mut self,
        name: &'static str,
        object: Object<'a>,
        state: Option<ImageState<'a>>,
    ) -> Res {
        let (last, tracked, fixed) = match state {
            Some(ImageState::Tracked(a)) => (*a, Some(a), None),
            Some(ImageState::Fixed(a)) => (a, None, Some(a)),
            None => (Access::Nothing, None, None),
        };
        let tracker = match object {
            // Earlier frames' uses are unknown: the first use waits for any of them.
            Object::Buffer(_) | Object::AddressBuffers | Object::TransientBuffer(_) => Tracker {
                writes: Uses::any_buffer_use(),
                visible: Uses::default(),
                reads: Uses::any_buffer_use(),
                last,
            },
            _ => Tracker {
                writes: Uses::of(last),
                visible: Uses::default(),
                reads: Uses::of(last),
                last,
            },
        };
        self.resources.push(Resource {
            name,
            object,
            tracked,
            fixed,
            tracker,
            touched: false,
        });
        Res(self.resources.len() - 1)
    }

    /// A buffer the GPU may have used in earlier frames.
    pub fn import_buffer(&mut self, name: &'static str, buffer: &'a Buffer) -> Res {
        self.push(name, Object::Buffer(buffer), None)
    }

    /// Buffers the GPU may have used in earlier frames that shaders reach by device address,
    /// as one resource (passes name their objects themselves).
    pub fn import_address_buffers(&mut self, name: &'static str) -> Res {
        self.push(name, Object::AddressBuffers, None)
    }

    /// A buffer the graph takes from its pool when it runs (see [`transient`]); earlier
    /// frames used the same object, so its first use waits for the uses the pool remembers.
    pub fn create_buffer(&mut self, desc: TransientBuffer) -> Res {
        self.push(desc.name, Object::TransientBuffer(desc), None)
    }

    /// An image the graph takes from its pool when it runs; its first use must discard.
    pub fn create_image(&mut self, name: &'static str, desc: ImageDesc) -> Res {
        let state = Some(ImageState::Fixed(Access::Nothing));
        let res = self.push(name, Object::TransientImage(desc), state);
        self.resources[res.0].fixed = None;
        res
    }

    /// Write the transient buffers that have bindings into `set` when the graph runs
    /// (before any pass records).
    pub fn bind_transients(&mut self, set: &'a DescriptorSet) {
        self.bind_sets.push(set);
    }

    /// An image and what is known of its state.
    pub fn import_image(
        &mut self,
        name: &'static str,
        image: &'a Image,
        state: ImageState<'a>,
    ) -> Res {
        self.push(name, Object::Image(image), Some(state))
    }

    /// A swapchain image just acquired; the frame must end with it in [`Access::Present`].
    pub fn import_swapchain(&mut self, name: &'static str, image: &'a SwapchainImage) -> Res {
        self.push(
            name,
            Object::Swapchain(image),
            Some(ImageState::Fixed(Access::Nothing)),
        )
    }

    /// Inputs the host wrote before the submission (frame block, tables, uploaded
    /// textures): declared for the frame's description, never ordered.
    pub fn host_input(&mut self, name: &'static str) -> Res {
        self.push(name, Object::Host, None)
    }

    /// Declare the next pass.
    pub fn pass<'g>(&'g mut self, name: &'static str) -> PassBuilder<'g, 'a> {
        PassBuilder {
            graph: self,
            name,
            uses: Vec::new(),
        }
    }

    /// Time the passes added until [`Self::end_scope`] as `name` (the frame report's pass
    /// timings).
    pub fn begin_scope(&mut self, name: &'static str) {
        self.nodes.push(Node::BeginScope(name));
    }

    /// End the scope begun last.
    pub fn end_scope(&mut self) {
        self.nodes.push(Node::EndScope);
    }

    /// Number of passes added so far.
    pub fn pass_count(&self) -> usize {
        self.nodes
            .iter()
            .filter(|n| matches!(n, Node::Pass { .. }))
            .count()
    }

    /// Record every pass in order with the barriers its uses need, creating the transient
    /// resources from `pool` first; returns the frame's description when asked for. Tracked
    /// images get their last use written back. Objects the pool replaced are in
    /// [`TransientPool::take_released`], whatever the result.
    pub fn run(
        self,
        rec: &mut CommandRecorder,
        profiler: &mut Profiler,
        pool: &mut TransientPool,
    ) -> GpuResult<Option<String>> {
        self.run_with(rec, Some(profiler), Some(pool))
    }

    /// [`Self::run`] without timing the scopes or a pool (one-off submissions that create
    /// no transients).
    pub fn run_untimed(self, rec: &mut CommandRecorder) -> GpuResult<Option<String>> {
        self.run_with(rec, None, None)
    }

    /// Take every transient from `pool`: `(index in the pool, what became of it)` per
    /// resource (`None` for imports); transient images start from their pooled last use.
    fn realize(
        &mut self,
        mut pool: Option<&mut TransientPool>,
    ) -> GpuResult<Vec<Option<(usize, Realized)>>> {
        let mut out = Vec::with_capacity(self.resources.len());
        for r in &mut self.resources {
            let taken = match (&r.object, pool.as_deref_mut()) {
                (Object::TransientBuffer(d), Some(p)) => {
                    let (i, how) = p.buffer(d)?;
                    // The last frame's uses of this object, not any use.
                    let last = Uses(p.buffer_last_uses(i));
                    (r.tracker.writes, r.tracker.reads) = (last, last);
                    Some((i, how))
                }
                (Object::TransientImage(d), Some(p)) => {
                    let (i, how) = p.image(d)?;
                    let last = p.image_at(i).1;
                    r.tracker.writes = Uses::of(last);
                    r.tracker.reads = Uses::of(last);
                    r.tracker.last = last;
                    Some((i, how))
                }
                (Object::TransientBuffer(_) | Object::TransientImage(_), None) => {
                    return Err(GpuError::Unsupported(format!(
                        "frame graph: {} is transient, but the graph runs without a pool",
                        r.name
                    )));
                }
                _ => None,
            };
            out.push(taken);
        }
        Ok(out)
    }

    fn run_with(
        mut self,
        rec: &mut CommandRecorder,
        mut profiler: Option<&mut Profiler>,
        mut pool: Option<&mut TransientPool>,
    ) -> GpuResult<Option<String>> {
        let realized = self.realize(pool.as_deref_mut())?;
        let pool_ref = pool.as_deref();
        if let Some(p) = pool_ref {
            for set in &self.bind_sets {
                p.write_bindings(set)?;
            }
        }
        let resources = PassResources {
            bound: bind(&self.resources, &realized, pool_ref),
            names: self.resources.iter().map(|r| r.name).collect(),
        };
        let mut text = String::new();
        let nodes = std::mem::take(&mut self.nodes);
        let mut count = 0;
        for node in nodes {
            match node {
                Node::BeginScope(name) => {
                    if let Some(p) = profiler.as_deref_mut() {
                        p.begin(rec, name);
                    }
                }
                Node::EndScope => {
                    if let Some(p) = profiler.as_deref_mut() {
                        p.end(rec);
                    }
                }
                Node::Pass { name, uses, record } => {
                    count += 1;
                    // A pass outside every scope is timed on its own: no pass escapes the
                    // frame report.
                    let own = open_own_scope(profiler.as_deref_mut(), rec, name);
                    let plan = self.plan(name, &uses)?;
                    if self.describe {
                        self.describe_pass(&mut text, count, name, &uses, &plan);
                    }
                    plan.record(rec, &resources.bound);
                    if let Some(record) = record {
                        record(rec, &resources)?;
                    }
                    if own && let Some(p) = profiler.as_deref_mut() {
                        p.end(rec);
                    }
                }
            }
        }
        if let Some(p) = profiler.as_deref_mut() {
            p.end(rec);
        }
        if let Some(plan) = self.finish(&mut text, count)? {
            let own = open_own_scope(profiler.as_deref_mut(), rec, RETURN_FIXED);
            plan.record(rec, &resources.bound);
            if own && let Some(p) = profiler {
                p.end(rec);
            }
        }
        drop(resources);
        if self.describe {
            self.describe_transients(&mut text, &realized, pool.as_deref());
        }
        self.keep_last_uses(&realized, pool);
        Ok(self.describe.then_some(text))
    }

    /// After the frame: tracked images keep their last state, and pooled transients their
    /// last uses, for the next frame's barriers.
    fn keep_last_uses(
        &mut self,
        realized: &[Option<(usize, Realized)>],
        mut pool: Option<&mut TransientPool>,
    ) {
        for (r, taken) in self.resources.iter_mut().zip(realized) {
            if let Some(t) = r.tracked.as_deref_mut() {
                *t = r.tracker.last;
            }
            match (&r.object, taken, pool.as_deref_mut()) {
                (Object::TransientImage(_), Some((i, _)), Some(p)) => {
                    p.set_image_last(*i, r.tracker.last)
                }
                (Object::TransientBuffer(_), Some((i, _)), Some(p)) => {
                    p.set_buffer_last_uses(*i, (r.tracker.writes | r.tracker.reads).0)
                }
                _ => {}
            }
        }
    }

    /// The barriers that return fixed-state images to their use, if any are needed.
    fn finish(&mut self, text: &mut String, count: usize) -> GpuResult<Option<Plan>> {
        let back: Vec<Use> = self
            .resources
            .iter()
            .enumerate()
            .filter_map(|(i, r)| {
                let fixed = r.fixed?;
                let keep = fixed == r.tracker.last || matches!(r.object, Object::Swapchain(_));
                (!keep).then_some(Use {
                    res: Res(i),
                    access: fixed,
                    discard: false,
                })
            })
            .collect();
        if back.is_empty() {
            return Ok(None);
        }
        let plan = self.plan(RETURN_FIXED, &back)?;
        if self.describe {
            self.describe_pass(text, count + 1, RETURN_FIXED, &back, &plan);
        }
        Ok(Some(plan))
    }

    /// The barriers before pass `pass` with `uses`, updating the trackers. A transient's
    /// first use must write it: its contents are an earlier frame's.
    fn plan(&mut self, pass: &str, uses: &[Use]) -> GpuResult<Plan> {
        let mut plan = Plan::default();
        // Uses of one resource by one pass are taken together.
        let mut order: Vec<Res> = Vec::new();
        for u in uses {
            if !order.contains(&u.res) {
                order.push(u.res);
            }
        }
        for res in order {
            let mine: Vec<&Use> = uses.iter().filter(|u| u.res == res).collect();
            let r = &mut self.resources[res.0];
            let transient = matches!(
                r.object,
                Object::TransientBuffer(_) | Object::TransientImage(_)
            );
            if transient && !r.touched && !mine.iter().any(|u| u.access.writes()) {
                return Err(GpuError::Unsupported(format!(
                    "frame graph: pass {pass} reads {}, which no earlier pass of the frame wrote",
                    r.name
                )));
            }
            r.touched = true;
            match r.object {
                Object::Host => {}
                Object::Buffer(_) | Object::AddressBuffers | Object::TransientBuffer(_) => {
                    plan_buffer(&mut plan, res, &mut r.tracker, &mine)
                }
                Object::Image(_) | Object::Swapchain(_) | Object::TransientImage(_) => {
                    plan_image(&mut plan, res, &mut r.tracker, mine[0])
                }
            }
        }
        Ok(plan)
    }

    /// The transients' sizes and whether they were reused.
    fn describe_transients(
        &self,
        text: &mut String,
        realized: &[Option<(usize, Realized)>],
        pool: Option<&TransientPool>,
    ) {
        let Some(pool) = pool else { return };
        let mut lines = Vec::new();
        for (r, taken) in self.resources.iter().zip(realized) {
            let Some((i, how)) = taken else { continue };
            let (bytes, asked) = match &r.object {
                Object::TransientBuffer(d) => (pool.buffer_at(*i).size, d.bytes),
                _ => {
                    let b = pool.image_at(*i).0.byte_size();
                    (b, b)
                }
            };
            let how = match how {
                Realized::New => "new".to_string(),
                Realized::Reused => "reused".to_string(),
                Realized::Grown(b) => format!("grown from {b}"),
                Realized::Shrunk(b) => format!("shrunk from {b}"),
                Realized::Recreated => "recreated".to_string(),
            };
            lines.push(format!(
                "       {}: {bytes} bytes ({asked} needed, {how})",
                r.name
            ));
        }
        if !lines.is_empty() {
            let _ = writeln!(text, "transient resources (pool {} bytes):", pool.bytes());
            let _ = writeln!(text, "{}", lines.join("\n"));
        }
    }

    fn describe_pass(&self, text: &mut String, n: usize, name: &str, uses: &[Use], plan: &Plan) {
        let _ = writeln!(text, "{n:>3}. {name}");
        let list = |reads: bool| -> Vec<String> {
            uses.iter()
                .filter(|u| u.access.writes() != reads)
                .map(|u| {
                    let d = if u.discard { ", discard" } else { "" };
                    format!("{} ({:?}{d})", self.resources[u.res.0].name, u.access)
                })
                .collect()
        };
        for (label, items) in [("reads", list(true)), ("writes", list(false))] {
            if !items.is_empty() {
                let _ = writeln!(text, "       {label}: {}", items.join(", "));
            }
        }
        for (res, prev, next) in &plan.buffer_log {
            let _ = writeln!(
                text,
                "       barrier: {} {} -> {:?}",
                self.resources[res.0].name,
                names(prev),
                next
            );
        }
        for b in &plan.images {
            let old = if b.discard {
                "UNDEFINED".to_string()
            } else {
                format!("{:?}", b.from.layout())
            };
            let _ = writeln!(
                text,
                "       barrier: {} {} -> {:?} (layout {old} -> {:?})",
                self.resources[b.res.0].name,
                names(&b.prev),
                b.next,
                b.next.layout()
            );
        }
    }
}

/// The object behind every resource.
fn bind<'r>(
    resources: &[Resource<'r>],
    realized: &[Option<(usize, Realized)>],
    pool: Option<&'r TransientPool>,
) -> Vec<Bound<'r>> {
    let from_pool = |taken: &Option<(usize, Realized)>, image: bool| match (taken, pool) {
        (Some((i, _)), Some(p)) if image => Bound::Image(p.image_at(*i).0),
        (Some((i, _)), Some(p)) => Bound::Buffer(p.buffer_at(*i)),
        _ => Bound::None,
    };
    resources
        .iter()
        .zip(realized)
        .map(|(r, taken)| match r.object {
            Object::Buffer(b) => Bound::Buffer(b),
            Object::Image(i) => Bound::Image(i),
            Object::Swapchain(s) => Bound::Swapchain(s),
            Object::Host | Object::AddressBuffers => Bound::None,
            Object::TransientBuffer(_) => from_pool(taken, false),
            Object::TransientImage(_) => from_pool(taken, true),
        })
        .collect()
}

fn names(list: &[Access]) -> String {
    let v: Vec<String> = list.iter().map(|a| format!("{a:?}")).collect();
    format!("[{}]", v.join("|"))
}

/// One image's planned dependency.
struct PlannedImage {
    res: Res,
    prev: Vec<Access>,
    from: Access,
    next: Access,
    discard: bool,
}

/// The barriers before one pass: one global memory dependency for all buffers, and the
/// image dependencies.
#[derive(Default)]
struct Plan {
    memory_prev: Uses,
    memory_next: Uses,
    buffer_log: Vec<(Res, Vec<Access>, Access)>,
    images: Vec<PlannedImage>,
}

impl Plan {
    fn record(&self, rec: &mut CommandRecorder, bound: &[Bound]) {
        let prev = self.memory_prev.list();
        let next = self.memory_next.list();
        let memory = (!next.is_empty()).then_some((&prev[..], &next[..]));
        let images: Vec<ImageBarrier> = self
            .images
            .iter()
            .filter_map(|p| {
                let image = match bound[p.res.0] {
                    Bound::Image(i) => BarrierImage::Image(i),
                    Bound::Swapchain(s) => BarrierImage::Swapchain(s),
                    _ => return None,
                };
                Some(ImageBarrier {
                    image,
                    prev: p.prev.clone(),
                    from: p.from,
                    next: p.next,
                    discard: p.discard,
                })
            })
            .collect();
        if memory.is_some() || !images.is_empty() {
            rec.pipeline_barrier(memory, &images);
        }
    }
}

/// A buffer's dependency before a pass using it as `mine`.
fn plan_buffer(plan: &mut Plan, res: Res, t: &mut Tracker, mine: &[&Use]) {
    let writes = mine.iter().any(|u| u.access.writes());
    let mut wait = Uses::default();
    let mut next = Uses::default();
    if writes {
        wait = t.writes | t.reads;
        for u in mine {
            next = next | Uses::of(u.access);
        }
        t.writes = Uses(
            mine.iter()
                .filter(|u| u.access.writes())
                .fold(0, |m, u| m | (1 << u.access as u32)),
        );
        // Reads in the same pass as the write are ordered by the pass itself; later reads
        // still need the write made visible to them.
        t.reads = Uses(
            mine.iter()
                .filter(|u| !u.access.writes())
                .fold(0, |m, u| m | (1 << u.access as u32)),
        );
        t.visible = Uses::default();
    } else {
        for u in mine {
            if !t.visible.contains(u.access) && !t.writes.is_empty() {
                wait = wait | t.writes;
                next = next | Uses::of(u.access);
            }
            t.visible = t.visible | Uses::of(u.access);
            t.reads = t.reads | Uses::of(u.access);
        }
    }
    if !next.is_empty() && !wait.is_empty() {
        plan.memory_prev = plan.memory_prev | wait;
        plan.memory_next = plan.memory_next | next;
        for a in next.list() {
            plan.buffer_log.push((res, wait.list(), a));
        }
    }
}

/// An image's dependency (and layout transition) before a pass using it as `u`.
fn plan_image(plan: &mut Plan, res: Res, t: &mut Tracker, u: &Use) {
    let a = u.access;
    let layout_change = u.discard || t.last.layout() != a.layout();
    let write = a.writes();
    let stale = !t.writes.is_empty() && !t.visible.contains(a);
    if write || layout_change || stale {
        let wait = if write || layout_change {
            t.writes | t.reads
        } else {
            t.writes
        };
        plan.images.push(PlannedImage {
            res,
            prev: wait.list(),
            from: t.last,
            next: a,
            discard: u.discard,
        });
    }
    if write || layout_change {
        // A transition is a write ordered before `a`.
        t.writes = Uses::of(a);
        t.visible = Uses::of(a);
        t.reads = Uses::of(a);
    } else {
        t.visible = t.visible | Uses::of(a);
        t.reads = t.reads | Uses::of(a);
    }
    t.last = a;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tracker() -> Tracker {
        Tracker {
            writes: Uses::default(),
            visible: Uses::default(),
            reads: Uses::default(),
            last: Access::Nothing,
        }
    }

    fn use_(access: Access) -> Use {
        Use {
            res: Res(0),
            access,
            discard: false,
        }
    }

    #[test]
    fn buffer_hazards() {
        let mut t = tracker();
        let mut p = Plan::default();
        // Nothing written yet: a read needs nothing.
        plan_buffer(&mut p, Res(0), &mut t, &[&use_(Access::ComputeRead)]);
        assert!(p.memory_next.is_empty());
        // A write waits for the read (WAR).
        let mut p = Plan::default();
        plan_buffer(&mut p, Res(0), &mut t, &[&use_(Access::ComputeReadWrite)]);
        assert!(p.memory_prev.contains(Access::ComputeRead));
        // A read waits for the write; the same read again does not.
        let mut p = Plan::default();
        plan_buffer(&mut p, Res(0), &mut t, &[&use_(Access::IndirectRead)]);
        assert!(p.memory_prev.contains(Access::ComputeReadWrite));
        assert!(p.memory_next.contains(Access::IndirectRead));
        let mut p = Plan::default();
        plan_buffer(&mut p, Res(0), &mut t, &[&use_(Access::IndirectRead)]);
        assert!(p.memory_next.is_empty());
        // Another stage's read still waits.
        let mut p = Plan::default();
        plan_buffer(&mut p, Res(0), &mut t, &[&use_(Access::VertexRead)]);
        assert!(p.memory_next.contains(Access::VertexRead));
        // A write waits for every read since the last write.
        let mut p = Plan::default();
        plan_buffer(&mut p, Res(0), &mut t, &[&use_(Access::TransferWrite)]);
        for a in [
            Access::ComputeReadWrite,
            Access::IndirectRead,
            Access::VertexRead,
        ] {
            assert!(p.memory_prev.contains(a), "{a:?}");
        }
    }

    #[test]
    fn image_transitions() {
        let mut t = tracker();
        let mut p = Plan::default();
        plan_image(&mut p, Res(0), &mut t, &use_(Access::ColorAttachment));
        assert_eq!(p.images.len(), 1);
        assert_eq!(p.images[0].from, Access::Nothing);
        // Sampled twice from different stages after one transition: the first read needs
        // the transition, the same read again nothing.
        let mut p = Plan::default();
        plan_image(&mut p, Res(0), &mut t, &use_(Access::SampledRead));
        assert_eq!(p.images[0].from, Access::ColorAttachment);
        let mut p = Plan::default();
        plan_image(&mut p, Res(0), &mut t, &use_(Access::SampledRead));
        assert!(p.images.is_empty());
        // A discarding write transitions from UNDEFINED and waits for the reads.
        let mut p = Plan::default();
        let mut u = use_(Access::TransferWrite);
        u.discard = true;
        plan_image(&mut p, Res(0), &mut t, &u);
        assert!(p.images[0].discard);
        assert_eq!(p.images[0].prev, vec![Access::SampledRead]);
    }
}
