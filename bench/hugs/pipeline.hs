-- a map / filter / zip pipeline over 100,000 elements
main = print (sum (zipWith (*) (map (* 3) xs) (filter (> 10) (map (+ 1) xs))))
  where xs = [1 .. 100000]
