//! The hair mesh model and its files: [`HairMesh`](hair_mesh::HairMesh) (scalp + layers), the
//! OBJ layer convention ([`obj_io`]), the styling parameters ([`style`]) and Yuksel's `.hair`
//! strand files ([`hair_file`]), and strand models read for fitting ([`strands`]: TressFX `.tfx`, `.hair`, Alembic `.abc`
//! curves through [`alembic`]).

pub mod alembic;
pub mod exact_array;
pub mod gltf;
pub mod hair_file;
pub mod hair_mesh;
pub mod obj_io;
pub mod strands;
pub mod style;
