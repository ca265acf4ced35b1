//! The scene: primitives in millimetres of the base frame (+X right, +Y up, seen from
//! above), each with a style role. No painter's types: both painters read this.

/// A point in the base frame, mm.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Mm {
    pub x: f64,
    pub y: f64,
}

impl Mm {
    pub const ORIGIN: Mm = Mm { x: 0.0, y: 0.0 };

    pub const fn new(x: f64, y: f64) -> Self {
        Mm { x, y }
    }

    /// The point at `radius` mm from `self` in direction `deg` (counter-clockwise from +X).
    pub fn polar(self, radius: f64, deg: f64) -> Mm {
        let (s, c) = deg.to_radians().sin_cos();
        Mm::new(self.x + radius * c, self.y + radius * s)
    }

    pub fn distance(self, other: Mm) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }
}

/// What a primitive is, which decides its colours, widths and text size ([`crate::render::Style`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Role {
    /// The 100 mm grid under everything.
    Grid,
    /// Reach of the right arm system (J2 > 0).
    EnvelopeRight,
    /// Reach of the left arm system (J2 < 0).
    EnvelopeLeft,
    /// The inner and outer reach radii.
    EnvelopeEdge,
    /// The singular band (arm nearly straight) near the outer radius.
    Singular,
    /// Joint angles beyond the J1 or J2 limits.
    LimitSector,
    /// The robot's base (the J1 housing).
    Base,
    /// Arm 1 and arm 2.
    Link,
    /// J1, J2 and the flange axis.
    Joint,
    /// The tool: the offset from the flange and the tool tip.
    Tool,
    /// The base frame's axes.
    FrameBase,
    /// The selected work frame's axes.
    FrameWork,
    /// The selected tool frame's axes (at the tool tip).
    FrameTool,
    /// Extra frames switched on by the operator.
    FrameOverlay,
    /// The next step's target pose, reachable.
    GhostReachable,
    /// The next step's target pose, reachable only by flipping the arm system.
    GhostFlip,
    /// The next step's target, refused by the checks.
    GhostRefused,
    /// A step's tool path: CP's straight line, PTP's joint-interpolated curve.
    CpLine,
    /// An interference zone of the controller (2A2H), in plan.
    Zone,
    /// A zone the next step's path enters (the pendant asks for a second press).
    ZoneEntered,
    /// A taught position (position table or teach list), numbered.
    Marker,
    /// The taught position selected in its table.
    MarkerSelected,
    /// The polled actual path, fading with age.
    Trail,
    /// The Z and R gauge's scale.
    Gauge,
    /// The Z and R gauge's marks of the actual pose.
    GaugeValue,
    /// Plain labels.
    Label,
    /// Something the operator must notice (stale position, a refusal).
    Warning,
}

/// Where a text's anchor sits on the text's box.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    Center,
    LeftCenter,
    RightCenter,
    CenterTop,
    CenterBottom,
    LeftBottom,
    LeftTop,
    RightBottom,
}

impl Anchor {
    /// The anchor's position on a box as fractions of its width and height from the
    /// top left corner.
    pub fn fractions(self) -> (f32, f32) {
        match self {
            Anchor::Center => (0.5, 0.5),
            Anchor::LeftCenter => (0.0, 0.5),
            Anchor::RightCenter => (1.0, 0.5),
            Anchor::CenterTop => (0.5, 0.0),
            Anchor::CenterBottom => (0.5, 1.0),
            Anchor::LeftBottom => (0.0, 1.0),
            Anchor::LeftTop => (0.0, 0.0),
            Anchor::RightBottom => (1.0, 1.0),
        }
    }
}

/// One primitive. Lengths are mm unless named `_px` (screen pixels, so labels and markers
/// stay legible at any zoom).
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Straight segments through the points (closed: back to the first).
    Polyline { points: Vec<Mm>, closed: bool },
    /// A circular arc, counter-clockwise from `start_deg` to `end_deg`.
    Arc {
        centre: Mm,
        radius: f64,
        start_deg: f64,
        end_deg: f64,
    },
    /// A circle of a radius in mm.
    Circle { centre: Mm, radius: f64 },
    /// A marker of a fixed screen size.
    Dot { centre: Mm, radius_px: f32 },
    /// A cross marker of a fixed screen size.
    Cross { centre: Mm, half_px: f32 },
    /// A filled polygon (any shape, convex or not): its points, the triangles that cover
    /// it (for painters that fill triangles) and its boundary in order (for painters that
    /// fill outlines), both as indices into the points.
    Fill {
        points: Vec<Mm>,
        triangles: Vec<[u32; 3]>,
        outline: Vec<u32>,
    },
    /// A line with an arrow head at `to`.
    Arrow { from: Mm, to: Mm },
    /// One line of text anchored at a point, moved by a screen offset (+y down).
    Text {
        at: Mm,
        text: String,
        anchor: Anchor,
        offset_px: [f32; 2],
    },
    /// The polled path, oldest point first; painted fading towards the oldest.
    Trail { points: Vec<Mm> },
}

/// A primitive with its role.
#[derive(Clone, Debug, PartialEq)]
pub struct Item {
    pub role: Role,
    pub shape: Shape,
}

/// Axis-aligned bounds in mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub min: Mm,
    pub max: Mm,
}

impl Bounds {
    pub fn width(&self) -> f64 {
        self.max.x - self.min.x
    }
    pub fn height(&self) -> f64 {
        self.max.y - self.min.y
    }
    pub fn centre(&self) -> Mm {
        Mm::new(
            (self.min.x + self.max.x) / 2.0,
            (self.min.y + self.max.y) / 2.0,
        )
    }
}

/// The whole picture: items in painting order (first underneath), and the bounds that
/// "fit" shows.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub items: Vec<Item>,
    pub bounds: Bounds,
}

impl Scene {
    /// The items of one role.
    pub fn with_role(&self, role: Role) -> impl Iterator<Item = &Shape> {
        self.items
            .iter()
            .filter(move |i| i.role == role)
            .map(|i| &i.shape)
    }
}

/// Points along an arc, at most `max_step_deg` apart, both ends included.
pub fn arc_points(
    centre: Mm,
    radius: f64,
    start_deg: f64,
    end_deg: f64,
    max_step_deg: f64,
) -> Vec<Mm> {
    let sweep = end_deg - start_deg;
    let n = ((sweep.abs() / max_step_deg.max(0.1)).ceil() as usize).clamp(1, 3600);
    (0..=n)
        .map(|i| centre.polar(radius, start_deg + sweep * i as f64 / n as f64))
        .collect()
}

/// Triangles of a fan from point 0 over points 1..n (a pie, or any convex polygon).
pub fn fan_triangles(n_points: usize) -> Vec<[u32; 3]> {
    (1..n_points.saturating_sub(1))
        .map(|i| [0, i as u32, i as u32 + 1])
        .collect()
}

/// A polygon whose points, in order, are its boundary and which a fan from its first
/// point covers (convex, or a pie from its centre).
pub fn fan_fill(points: Vec<Mm>) -> Shape {
    Shape::Fill {
        triangles: fan_triangles(points.len()),
        outline: (0..points.len() as u32).collect(),
        points,
    }
}
