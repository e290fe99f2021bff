-- a scene tree 1000 deep (a chain of Unions of half-spaces) moved by a
-- Shift written as qcs's prelude writes it, 200 times, each time walked to
-- sum the planes' offsets
type Vector = (Double, Double, Double)
data Solid = Halfspace (Vector, Double) | Union Solid Solid

dot :: Vector -> Vector -> Double
dot (a, b, c) (x, y, z) = a * x + b * y + c * z

shift :: Vector -> Solid -> Solid
shift v (Union a b) = Union (shift v a) (shift v b)
shift v (Halfspace (nv, d)) = Halfspace (nv, d + dot nv v)

chain :: Double -> Solid
chain 0 = Halfspace ((1, 0, 0), 0)
chain d = Union (Halfspace ((0, 1, 0), d)) (chain (d - 1))

t :: Solid
t = chain 1000

offsets :: Solid -> Double
offsets (Union a b) = offsets a + offsets b
offsets (Halfspace (_, d)) = d

main = print (round (sum [offsets (shift (k, k, k) t) | k <- [1 .. 200]]) :: Integer)
