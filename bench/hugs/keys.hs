-- 100,000 soft-object keys built as examples/soft-cloud.qcs builds them,
-- then taken apart: the floor of the sum of their centres' coordinates
data Key = Key (Double, Double, Double) Double Double

n :: Double
n = 100000
l :: Double
l = 0.5 * n ** (1 / 3)

fract :: Double -> Double
fract x = x - fromIntegral (floor x :: Int)

key :: Double -> Key
key k = Key (fract (0.5 + 0.8191725134 * k) * l,
             fract (0.5 + 0.6710436067 * k) * l,
             fract (0.5 + 0.5497004779 * k) * l) 0.6 1

centre :: Key -> Double
centre (Key (x, y, z) _ _) = x + y + z

main = print (floor (sum (map centre [key k | k <- [0 .. n - 1]])) :: Integer)
