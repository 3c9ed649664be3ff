"""How a vehicle moves (a point or a flown quadrotor), contact. Imports: config, world, codegen."""
